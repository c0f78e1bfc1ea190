"""Adversarial options: values that would fail every task alike, or the command itself, are
one line before any work."""
import pytest

from rigedit.batch.engine import Engine
from rigedit.batch.inputs import BatchUsageError
from rigedit.batch.tasks import check_options
from rigedit.cli.main import main


@pytest.mark.parametrize("timeout", [float("nan"), 0, -1, float("inf"), "soon"])
def test_a_timeout_that_is_no_time_is_refused(timeout):
    with pytest.raises(BatchUsageError, match="--timeout"):
        Engine(timeout=timeout)


@pytest.mark.parametrize("options, message", [
    ({"up": "q"}, "expected an axis"),               # every task failed with this ValueError
    ({"up": "y", "forward": "-y"}, "at right angles"),
])
def test_autorig_axes_that_make_no_sense_are_refused(options, message):
    with pytest.raises(BatchUsageError, match=message):
        check_options("autorig", options)


def test_good_autorig_axes_pass():
    assert check_options("autorig", {"up": "+Z", "forward": "-x"})["up"] == "+Z"


@pytest.mark.parametrize("args, message", [
    (["--scheduler", "ucx://127.0.0.1:1", "--timeout", "1"], "does not answer"),  # TypeError
    (["--timeout", "nan"], "--timeout"),
])
def test_the_command_says_one_line_and_exits_2(tmp_path, capsys, args, message):
    out = tmp_path / "out"
    assert main(["batch", "convert", "humanoid", "--to", "glb", "-o", str(out)] + args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("rigedit: error:") and message in err[0]
    assert not out.exists()


@pytest.mark.parametrize("text, message", [("{", "invalid JSON"), ("[1, 2]", "expected an object"),
                                           (None, "cannot read")])
def test_a_joint_map_that_is_no_map_is_refused_before_any_task(tmp_path, text, message):
    path = tmp_path / "map.json"
    if text is None:
        path.mkdir()   # a folder given as the map
    else:
        path.write_text(text)
    with pytest.raises(BatchUsageError, match=f"retarget --map: .*{message}"):
        check_options("retarget", {"to": ["humanoid"], "map": str(path)})


def test_a_good_joint_map_passes(tmp_path):
    path = tmp_path / "map.json"
    path.write_text('{"Hips": "Hips"}')
    assert check_options("retarget", {"to": ["humanoid"], "map": str(path)})["map"] == str(path)


def test_an_empty_outdir_is_refused_not_the_working_folder(tmp_path, monkeypatch, capsys):
    # -o "$OUT" with OUT unset wrote the outputs, manifest and report into the working folder
    monkeypatch.chdir(tmp_path)
    assert main(["batch", "convert", "humanoid", "--to", "glb", "-o", ""]) == 2
    assert "empty name" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_a_target_that_is_no_rig_is_refused_before_any_task(tmp_path):
    (tmp_path / "chars").mkdir()
    (tmp_path / "hero.txt").write_text("x")
    for target, message in ((tmp_path / "chars", "folder without one"),
                            (tmp_path / "hero.txt", "expected a rig file")):
        with pytest.raises(BatchUsageError, match=f"retarget --to .*{message}"):
            check_options("retarget", {"to": [str(target)]})
    rig = tmp_path / "fox"
    rig.mkdir()
    (rig / "skeleton.json").write_text("{}")
    assert check_options("retarget", {"to": [str(rig), "humanoid"]})["to"] == \
        sorted([str(rig), "humanoid"])
