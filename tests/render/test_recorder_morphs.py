"""The recorder plays a clip's morph weight tracks, and leaves the editor's weights as they were."""
import imageio.v3 as iio
import numpy as np

from builders import cylinder_rig
from morph_builders import add_targets
from rigedit.animation.clip import Clip
from rigedit.animation.morph_track import WeightTrack
from rigedit.render.recorder import record_clip

SIZE = (160, 120)


def _record(rig, track, path):
    clip = Clip("bulge", rig.skeleton, morph_tracks={"bulge": track})
    # a fixed camera: the framing must not follow the shape
    camera = {"position": (0.0, 1.5, 12.0), "focal_point": (0.0, 1.5, 0.0),
              "up": (0.0, 1.0, 0.0), "view_angle": 30.0}
    assert record_clip(rig, clip, path, fps=4, duration=1.0, size=SIZE, camera=camera,
                       show_floor=False) == 4
    frames = np.stack(list(iio.imiter(path))).astype(int)
    # (a GIF writer may fold identical frames into one: compare the last with the first)
    return np.abs(frames[-1] - frames[0]).mean()


def test_a_clip_of_weights_only_moves_the_video_and_the_shown_weights_come_back(tmp_path):
    rig = add_targets(cylinder_rig(with_clip=False))
    rig.binding.set_morph_weights([0.0, 0.3])          # what the editor shows
    # the top fifth of the cylinder swells by a tenth of its height at weight 1
    moving = _record(rig, WeightTrack([0.0, 1.0], [0.0, 1.0]), tmp_path / "a.gif")
    held = _record(rig, WeightTrack([0.0, 1.0], [0.5, 0.5]), tmp_path / "b.gif")
    assert held == 0.0 and moving > 0.3      # measured 0.79 (mean absolute, 0-255)
    np.testing.assert_array_equal(rig.binding.morph_weights, [0.0, 0.3])
