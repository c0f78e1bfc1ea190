import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from builders import cylinder_rig
from rigedit.cli.main import main
from rigedit.io import save_rig_folder


@pytest.fixture
def rig_dir(tmp_path):
    save_rig_folder(tmp_path / "cyl", cylinder_rig())
    return tmp_path / "cyl"


def test_info_prints_key_value_lines(rig_dir, capsys):
    assert main(["info", str(rig_dir)]) == 0
    out = dict(line.split(": ", 1) for line in capsys.readouterr().out.splitlines())
    assert out["vertices"] == str(31 * 24 + 2)
    assert out["faces"] == str(2 * 30 * 24 + 2 * 24)
    assert out["joints"] == "3" and out["bones"] == "2" and out["clips"] == "bend"


def test_list_prints_clip_durations(rig_dir, capsys):
    assert main(["list", str(rig_dir)]) == 0
    assert capsys.readouterr().out.split() == ["bend", "1.000s", "loop"]


def test_weights_command_writes_npz(rig_dir, tmp_path, capsys):
    out = tmp_path / "w.npz"
    assert main(["weights", str(rig_dir), "--max-influences", "2", "-o", str(out)]) == 0
    with np.load(out) as data:
        assert data["indices"].shape == (31 * 24 + 2, 2)
        assert np.allclose(data["weights"].sum(axis=1), 1.0, atol=1e-6)


def test_quiet_prints_nothing_but_errors(rig_dir, tmp_path, capsys):
    """-q on every command: the report lines and the warnings go (a weights file computed on
    load warns), an error line stays."""
    from rigedit.cli.main import build_parser

    sub = next(a for a in build_parser()._actions if a.dest == "command")
    for name, parser in sub.choices.items():
        assert any("-q" in a.option_strings for a in parser._actions), name
    (rig_dir / "weights.npz").unlink()   # loading then computes them, with a warning
    assert main(["info", str(rig_dir)]) == 0
    loud = capsys.readouterr()
    assert "vertices:" in loud.out and "rigedit: warning" in loud.err
    assert main(["export", str(rig_dir), "-o", str(tmp_path / "c.glb"), "-q"]) == 0
    quiet = capsys.readouterr()
    assert quiet.out == "" and quiet.err == "" and (tmp_path / "c.glb").stat().st_size > 0
    assert main(["info", str(tmp_path / "none"), "-q"]) == 2
    assert "rigedit: error" in capsys.readouterr().err


@pytest.mark.parametrize("argv,msg", [
    (["info", "{missing}"], "expected a rig folder, got nothing (not found)"),
    (["render", "nope", "--rig", "{rig}", "-o", "{tmp}/x.mp4"], "unknown clip 'nope'"),
    (["render", "bend", "--rig", "{rig}", "-o", "{tmp}/x.avi"], "expected a video file name"),
    (["render", "bend", "--rig", "{rig}", "-o", "{tmp}/x.mp4", "--size", "big"], "--size"),
    (["weights", "{rig}", "--method", "voodoo", "-o", "{tmp}/w.npz"], "unknown weights method"),
])
def test_bad_input_is_one_line_and_exit_2(rig_dir, tmp_path, argv, msg):
    argv = [a.format(missing=tmp_path / "none", rig=rig_dir, tmp=tmp_path) for a in argv]
    proc = subprocess.run([sys.executable, "-m", "rigedit", *argv], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 2
    err_lines = [line for line in proc.stderr.splitlines() if line.startswith("rigedit: error")]
    assert len(err_lines) == 1 and msg in err_lines[0]
    assert "Traceback" not in proc.stderr


def test_malformed_skeleton_names_the_file(rig_dir, capsys):
    (rig_dir / "skeleton.json").write_text('{"joints": [{"name": 3}]}')
    assert main(["info", str(rig_dir)]) == 2
    err = capsys.readouterr().err
    assert "skeleton.json" in err and "expected 'name'" in err


def test_render_end_to_end_mp4_and_gif(rig_dir, tmp_path):
    import imageio.v3 as iio

    mp4 = tmp_path / "bend.mp4"
    assert main(["render", "bend", "--rig", str(rig_dir), "-o", str(mp4), "--fps", "8",
                 "--size", "96x64", "-q"]) == 0
    frames = iio.imread(mp4)
    assert frames.shape == (8, 64, 96, 3)   # duration 1 s at 8 fps
    # The clip bends the cylinder: the first and middle frames differ.
    assert np.abs(frames[0].astype(int) - frames[4].astype(int)).mean() > 5.5  # measured 11.1
    gif = tmp_path / "bend.gif"
    assert main(["render", "bend", "--rig", str(rig_dir), "-o", str(gif), "--fps", "4",
                 "--duration", "0.5", "--size", "64x48", "--angle", "90", "-q"]) == 0
    g = iio.imread(gif)
    assert g.shape[0] == 2 and g.shape[1:3] == (48, 64)


# ---------------------------------------------------------------------- output files
@pytest.mark.parametrize("argv", [
    ["weights", "{rig}", "-o", "{out}/w.npz"],
    ["render", "bend", "--rig", "{rig}", "-o", "{out}/v.mp4", "-q"],
    ["export", "{rig}", "-o", "{out}/copy"],
])
def test_missing_output_folder_is_one_error_for_every_command(rig_dir, tmp_path, capsys, argv):
    out = tmp_path / "no" / "such"
    argv = [a.format(rig=rig_dir, out=out) for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(f"rigedit: error: {argv[argv.index('-o') + 1]}:")
    assert "expected an existing folder" in err[0]
    assert not (tmp_path / "no").exists()   # no folder created


def _hidden(folder):
    return [p.name for p in Path(folder).iterdir() if p.name.startswith(".")]


@pytest.mark.parametrize("argv", [
    ["weights", "{rig}", "-o", "{out}"],
    ["render", "bend", "--rig", "{rig}", "-o", "{out}", "-q", "--size", "32x32", "--fps", "2"],
])
def test_output_that_cannot_be_written_is_named_not_its_temporary_file(rig_dir, tmp_path,
                                                                        capsys, argv):
    """An output path that is an existing folder: the error names it, no temp file stays."""
    out = tmp_path / "taken" / ("w.npz" if argv[0] == "weights" else "v.mp4")
    out.mkdir(parents=True)
    assert main([a.format(rig=rig_dir, out=out) for a in argv]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(f"rigedit: error: {out}:"), err
    assert f".{out.name}." not in err[0]
    assert _hidden(out.parent) == []


def test_atomic_write_errors_name_the_target_not_the_temporary_file(tmp_path):
    from rigedit.io.atomic import write_json

    target = tmp_path / "x.json"
    target.mkdir()
    with pytest.raises(OSError) as info:
        write_json(target, {})
    assert info.value.filename == str(target) and _hidden(tmp_path) == []


def _start_render(rig_dir, out, extra=()):
    """A ``rigedit render`` long enough to interrupt (thousands of tiny frames), started in
    its own session, headless (no DISPLAY: the recorder renders through EGL)."""
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    return subprocess.Popen(
        [sys.executable, "-m", "rigedit", "render", "bend", "--rig", str(rig_dir), "-o",
         str(out), "--size", "32x32", "--fps", "60", "--duration", "300", "-q", *extra],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
        env=env)


def test_interrupted_render_removes_its_temporary_file(rig_dir, tmp_path):
    """Ctrl-C (SIGINT to the whole process group, ffmpeg too) and SIGTERM (to the process)
    in the middle of MP4 and GIF renders: exit 130/143, one line, no temporary file left."""
    # (signal, video, to the whole group, seconds after the temporary file appears): at 0 the
    # signal lands while ffmpeg starts, before the first frame
    cases = [(signal.SIGINT, ".mp4", True, 0.5), (signal.SIGTERM, ".gif", False, 0.5),
             (signal.SIGTERM, ".mp4", False, 0.5), (signal.SIGINT, ".mp4", True, 0.0)]
    runs = []
    try:
        for i, (sig, suffix, group, delay) in enumerate(cases):   # together: startup dominates
            out = tmp_path / f"out{i}" / f"v{suffix}"
            out.parent.mkdir()
            runs.append((sig, group, delay, out, _start_render(rig_dir, out)))
        for sig, group, delay, out, proc in runs:
            deadline = time.monotonic() + 120
            while (not _hidden(out.parent) and proc.poll() is None
                   and time.monotonic() < deadline):
                time.sleep(0.01)
            assert proc.poll() is None and _hidden(out.parent), "the render did not start"
            time.sleep(delay)
            (os.killpg if group else os.kill)(proc.pid, sig)
        for sig, group, delay, out, proc in runs:
            _, err = proc.communicate(timeout=60)
            assert proc.returncode == 128 + sig
            assert err.splitlines() == [f"rigedit: interrupted by {signal.Signals(sig).name}"]
            assert list(out.parent.iterdir()) == []   # no temporary file, no output
    finally:   # a failed run must not leave renders going for minutes
        for *_, proc in runs:
            if proc.poll() is None:
                proc.kill()
                proc.wait()


def test_a_folder_that_refuses_the_temporary_file_is_reported_as_the_target(tmp_path,
                                                                            monkeypatch):
    import tempfile

    from rigedit.io.atomic import write_json

    def refuse(prefix="", suffix="", dir=None):
        raise PermissionError(13, "Permission denied", f"{dir}/{prefix}abc{suffix}")

    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    from rigedit.errors import RigWriteError   # an OSError too, with errno EACCES

    with pytest.raises(RigWriteError) as info:
        write_json(tmp_path / "x.json", {})
    assert info.value.filename == str(tmp_path / "x.json") and info.value.errno == 13
    assert "Permission denied" in str(info.value) and ".x.json." not in str(info.value)


def test_a_swallowed_interrupt_is_raised_again_and_a_second_one_waits():
    """A VTK callback swallows the exception a signal raised inside it: the job's next
    check raises it again; a second signal does not break into the clean-up."""
    from rigedit.cli.output import Interrupted, check_interrupted, interruptible

    with pytest.raises(Interrupted) as info:
        with interruptible():
            check_interrupted()                       # nothing received yet
            try:
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(1)                          # the handler runs here
            except BaseException:                      # as a VTK callback would
                pass
            os.kill(os.getpid(), signal.SIGINT)        # during clean-up: only recorded
            time.sleep(0.05)
            check_interrupted()
    assert info.value.exit_status == 143
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL   # handlers restored
