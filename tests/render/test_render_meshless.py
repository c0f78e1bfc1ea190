"""`rigedit render` and `rigedit info` on a BVH file: a skeleton with no mesh."""
import imageio.v2 as imageio
import numpy as np

from rigedit.cli.main import main
from test_ui_meshless import BVH


def test_cli_render_of_a_bvh_moves(tmp_path, capsys):
    src = tmp_path / "walk.bvh"
    src.write_text(BVH)
    out = tmp_path / "walk.gif"
    assert main(["render", "take", "--rig", str(src), "--scale", "0.01", "-o", str(out),
                 "--size", "160x120", "--fps", "4", "-q"]) == 0
    frames = [f[..., :3].astype(int) for f in imageio.mimread(out)]
    assert len(frames) == 4
    # something is drawn (bones: dark blue on the light background) and it moves
    blue = [np.sum((f[..., 2] > f[..., 0] + 60)) for f in frames]
    assert min(blue) > 20
    assert max(np.abs(frames[0] - f).max() for f in frames[1:]) > 60


def test_cli_info_reports_units_and_frames(tmp_path, capsys):
    src = tmp_path / "walk.bvh"
    src.write_text(BVH)
    assert main(["info", str(src)]) == 0
    captured = capsys.readouterr()
    out = dict(line.split(": ", 1) for line in captured.out.splitlines())
    assert out["vertices"] == "0" and out["joints"] == "5" and out["clips"] == "take"
    assert out["units"].startswith("guessed centimetres")
    assert "Y up" in out["frames"]
    assert "rigedit: warning:" in captured.err and "guessed centimetres" in captured.err
    # bounds come from the skeleton (joints and End Sites), in metres
    lo = [float(v) for v in out["bounds_min"].split()]
    hi = [float(v) for v in out["bounds_max"].split()]
    # (the left foot's End Site at 0.05 m, the head's at 1.7 m)
    np.testing.assert_allclose([lo[1], hi[1]], [0.05, 1.7], atol=1e-9)
