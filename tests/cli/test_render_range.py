"""``rigedit render --start S --end E``: the frames of [S, E) at the frame rate, the first one
the pose at S; bad ranges are one line and exit 2 before any rendering."""
import subprocess
import sys

import imageio.v3 as iio
import numpy as np
import pytest

from builders import cylinder_rig
from rigedit.cli.main import main
from rigedit.io import save_rig_folder
from rigedit.render.recorder import record_clip


@pytest.fixture(scope="module")
def rig_dir(tmp_path_factory):
    folder = tmp_path_factory.mktemp("range") / "cyl"
    save_rig_folder(folder, cylinder_rig())    # clip "bend": 1 s, 0 -> 60 -> 0 degrees
    return folder


def _render(rig_dir, out, *extra):
    return main(["render", "bend", "--rig", str(rig_dir), "-o", str(out), "--fps", "8",
                 "--size", "64x48", "-q", *extra])


def test_start_end_renders_that_part(rig_dir, tmp_path):
    out = tmp_path / "part.gif"
    assert _render(rig_dir, out, "--start", "0.25", "--end", "0.75") == 0
    assert iio.imread(out, index=None).shape[0] == 4   # 0.25, 0.375, 0.5, 0.625
    assert _render(rig_dir, out, "--start", "0.5") == 0   # to the clip's end
    assert iio.imread(out, index=None).shape[0] == 4
    assert _render(rig_dir, out, "--start", "0.5", "--duration", "0.25") == 0
    assert iio.imread(out, index=None).shape[0] == 2
    # past the end a looping clip plays again from its start: 1.5 s of a 1 s clip
    assert _render(rig_dir, out, "--start", "0.5", "--end", "2") == 0
    frames = iio.imread(out, index=None).astype(int)
    assert frames.shape[0] == 12
    np.testing.assert_array_equal(frames[0], frames[8])   # t = 0.5 and t = 1.5


def test_the_cli_renders_what_record_clip_renders_from_start(rig_dir, tmp_path):
    """The command hands S and the range to the recorder (same frames as the library's)."""
    import rigedit

    cli, lib = tmp_path / "cli.gif", tmp_path / "lib.gif"
    assert _render(rig_dir, cli, "--start", "0.25", "--end", "0.5") == 0
    rig = rigedit.load_rig(rig_dir)
    assert record_clip(rig, rig.clips["bend"], lib, fps=8, size=(64, 48), start=0.25,
                       duration=0.25) == 2
    np.testing.assert_array_equal(iio.imread(cli, index=None), iio.imread(lib, index=None))


def test_the_first_frame_is_the_pose_at_start():
    """With the camera held (as the editor's dialog holds it), the first frame of a range
    from S is the frame of a one-frame render at S, and not the frame at 0."""
    import tempfile
    from pathlib import Path

    rig = cylinder_rig()
    clip = rig.clips["bend"]
    camera = {"position": (0.0, 1.5, 9.0), "focal_point": (0.0, 1.5, 0.0), "up": (0, 1, 0)}
    with tempfile.TemporaryDirectory() as tmp:
        def frames(start, duration):
            path = Path(tmp) / f"{start}-{duration}.gif"
            record_clip(rig, clip, path, fps=8, size=(64, 48), start=start, duration=duration,
                        camera=camera, follow_root=False)
            return iio.imread(path, index=None).astype(int)

        part = frames(0.5, 0.5)
        assert len(part) == 4
        at_s, at_0 = frames(0.5, 0.125)[0], frames(0.0, 0.125)[0]
    np.testing.assert_array_equal(part[0], at_s)
    assert np.abs(part[0] - at_0).mean() > 1.0    # the bend shows


@pytest.mark.parametrize("extra,msg", [
    (["--start", "nan"], "--start: expected a finite number"),
    (["--start", "-1"], "--start: expected a finite number of seconds >= 0, got -1"),
    (["--start", "0.5", "--end", "0.5"], "--end: expected a finite time after --start"),
    (["--end", "inf"], "--end: expected a finite time"),
    (["--start", "1", "--end", "5000"], "--end: expected at most 3600 s"),
    (["--end", "0.5", "--duration", "0.5"], "--end and --duration both"),
    (["--start", "1"], "--start 1 is past the end of clip 'bend' (1 s)"),
    (["--start", "7.5", "--end", "8"], "past the end of clip 'bend'"),
])
def test_a_bad_range_is_one_line_and_exit_2(rig_dir, tmp_path, capsys, extra, msg):
    out = tmp_path / "x.mp4"
    assert main(["render", "bend", "--rig", str(rig_dir), "-o", str(out), *extra]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rigedit: error") and msg in lines[0], lines
    assert not out.exists()


def test_the_command_line_says_no_traceback(rig_dir, tmp_path):
    """The same through the real command: exit status 2, one line on stderr."""
    proc = subprocess.run([sys.executable, "-m", "rigedit", "render", "bend", "--rig",
                           str(rig_dir), "-o", str(tmp_path / "x.gif"), "--start", "inf"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr
    assert "--start: expected a finite number" in proc.stderr
