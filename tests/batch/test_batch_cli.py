"""``rigedit batch``: exit 2 for bad input before any work, exit 1 with a failed row for a
broken file among good ones, and a resumed run that does nothing."""
import json

import pytest

import rigedit
from batch_helpers import free_port, broken_bvh, litter, make_motions, run_cli
from rigedit.cli.main import main


@pytest.mark.parametrize("args, message", [
    (["convert", "humanoid", "--to", "obj"], "convert --to: expected one of"),
    (["render", "humanoid", "--clip", "walk", "--size", "15x15"], "--size"),
    (["retarget", "nowhere/*.bvh", "--to", "humanoid"], "matches no file"),
    (["retarget", "humanoid", "--to", "no_such_rig.glb"], "no such rig"),
    (["convert", "humanoid", "--to", "glb", "--workers", "0"], "--workers"),
])
def test_bad_options_exit_2_before_any_work(tmp_path, capsys, args, message):
    out = tmp_path / "out"
    assert main(["batch"] + args + ["-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("rigedit: error:") and message in err[0]
    assert not out.exists()   # nothing made, nothing started


def test_an_outdir_that_cannot_be_made_or_is_a_file_exits_2(tmp_path, capsys):
    afile = tmp_path / "afile"
    afile.write_text("")
    for out, message in ((tmp_path / "no" / "out", "existing folder"),
                         (afile, "got a file"), ("/proc/rigedit-batch-out", "cannot make")):
        assert main(["batch", "convert", "humanoid", "--to", "glb", "-o", str(out)]) == 2
        assert message in capsys.readouterr().err


def test_a_scheduler_that_does_not_answer_exits_2_within_seconds(tmp_path, capsys):
    import time

    out = tmp_path / "out"
    t0 = time.perf_counter()
    code = main(["batch", "convert", "humanoid", "--to", "glb", "-o", str(out),
                 "--scheduler", f"tcp://127.0.0.1:{free_port()}", "--timeout", "1"])
    assert code == 2 and time.perf_counter() - t0 < 15
    assert "does not answer within 1 s" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.slow
def test_a_broken_file_among_good_ones_is_one_failed_row_exit_1_and_resume(tmp_path):
    good = make_motions(tmp_path / "in", 3)
    broken_bvh(tmp_path / "in")
    out = tmp_path / "out"
    args = ["batch", "retarget", tmp_path / "in", "--to", "humanoid", "-o", out,
            "--workers", "2", "--no-thumbnails"]
    first = run_cli(*args)
    assert first.returncode == 1, first.stderr
    assert "1 of 4 tasks failed" in first.stderr
    tasks = json.loads((out / "manifest.json").read_text())["tasks"]
    assert sorted(t["status"] for t in tasks) == ["failed", "ok", "ok", "ok"]
    (bad,) = [t for t in tasks if t["status"] == "failed"]
    assert bad["input"].endswith("broken.bvh") and "broken.bvh" in bad["error"]
    for t in tasks:
        if t["status"] == "ok":
            assert len(rigedit.load_rig(out / t["outputs"][0]).clips) == 1
    assert litter(out) == []
    # fixed: the resumed run runs that one task only, then a second resume runs none
    broken = tmp_path / "in" / "broken.bvh"
    broken.write_bytes(good[0].read_bytes())
    second = run_cli(*args, "--resume")
    assert second.returncode == 0, second.stderr
    assert "4 tasks: 1 run, 3 skipped" in second.stdout
    before = {p.name: p.read_bytes() for p in (out / "manifest").glob("*.json")}
    assert len(before) == 4
    third = run_cli(*args, "--resume")
    assert third.returncode == 0 and "4 tasks: 0 run, 4 skipped" in third.stdout
    assert {p.name: p.read_bytes() for p in (out / "manifest").glob("*.json")} == before
    quiet = run_cli(*args, "--resume", "-q")
    assert quiet.returncode == 0 and quiet.stdout == quiet.stderr == ""
