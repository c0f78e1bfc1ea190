"""``rigedit compress`` and ``rigedit export --compress`` on bad input: one line naming the
problem, exit 2, nothing written (checked before the compressor runs)."""
from __future__ import annotations

import pytest

from rigedit.cli.main import main


@pytest.mark.parametrize("option,value", [
    ("--max-error", "0"), ("--max-error", "-0.01"), ("--max-error", "nan"),
    ("--max-error", "inf"), ("--max-error", "1e9"), ("--shell", "0"), ("--shell", "-3"),
    ("--shell", "nan")])
@pytest.mark.parametrize("command", ["compress", "export"])
def test_a_bad_number_is_one_line_and_nothing_is_written(tmp_path, capsys, command, option,
                                                         value):
    argv = [command, "humanoid", f"{option}={value}", "-o", str(tmp_path / "out.glb")]
    if command == "export":
        argv.append("--compress")
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"rigedit: error: {option}:"), err
    assert "centimetres" in err[0]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("command", ["compress", "export"])
def test_an_unknown_clip_names_the_rig_and_the_clip(tmp_path, capsys, command):
    argv = [command, "humanoid", "--clip", "walk", "--clip", "moonwalk", "-o",
            str(tmp_path / "out.glb")] + (["--compress"] if command == "export" else [])
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "humanoid" in err[0] and "'moonwalk'" in err[0]
    assert "idle, walk, wave" in err[0]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv,msg", [
    (["compress", "humanoid", "--meshopt", "-o", "{tmp}/folder"], "--meshopt: expected a .glb"),
    (["export", "humanoid", "--compress", "-o", "{tmp}/x.fbx"], "--compress: expected a .glb"),
    (["export", "humanoid", "--compress", "-o", "{tmp}/x.bvh"], "--compress: expected a .glb"),
    (["export", "humanoid", "--max-error", "0.1", "-o", "{tmp}/x.glb"], "go with --compress"),
    (["export", "humanoid", "--meshopt", "-o", "{tmp}/x.glb"], "go with --compress"),
    (["compress", "humanoid", "-o", "{tmp}/no/such/folder/x.glb"], "no/such/folder"),
])
def test_options_that_do_not_fit(tmp_path, capsys, argv, msg):
    assert main([a.format(tmp=tmp_path) for a in argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and msg in err[0], err
    assert list(tmp_path.iterdir()) == []
