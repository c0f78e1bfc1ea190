import subprocess
import sys

import numpy as np
import pytest

from builders import cylinder_rig
from rigedit.cli import main
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
    assert np.abs(frames[0].astype(int) - frames[4].astype(int)).mean() > 1.0
    gif = tmp_path / "bend.gif"
    assert main(["render", "bend", "--rig", str(rig_dir), "-o", str(gif), "--fps", "4",
                 "--duration", "0.5", "--size", "64x48", "--angle", "90", "-q"]) == 0
    g = iio.imread(gif)
    assert g.shape[0] == 2 and g.shape[1:3] == (48, 64)
