"""BVH out: reading the written file back gives the same joint positions per frame."""
import warnings

import numpy as np
import pytest

import rigedit
from builders import chain_skeleton
from rigedit.animation import Clip, Track
from rigedit.cli.main import main
from rigedit.io.bvh import load_bvh
from rigedit.io.bvh_write import BvhFramesWarning, bvh_frame_times, save_bvh
from rigedit.model import Skeleton
from rigedit.model.transforms import euler_to_quat
from rigedit.rig import Rig
from bvh_figures import humanoid_bvh
from test_io_bvh import DATA, FILES, shared


def positions_per_frame(rig, clip, times):
    return np.stack([rig.joint_matrices(clip.sample(t))[:, :3, 3] for t in times])


def assert_same_motion(rig, clip, back, times):
    """Joint positions of ``back``'s clip at each frame equal the original's (by name)."""
    back_clip = next(iter(back.clips.values()))
    n = len(back_clip.tracks[(back.skeleton.names[0], "rotation")].times)
    assert n == len(times)
    frame_time = (back_clip.duration / (n - 1)) if n > 1 else 0.0
    want = positions_per_frame(rig, clip, times)
    order = [back.skeleton.names.index(name) for name in rig.skeleton.names]
    got = positions_per_frame(back, back_clip, np.arange(n) * frame_time)[:, order]
    height = np.ptp(want[..., 1]) or 1.0
    err = np.abs(got - want).max()
    assert err <= 1e-6 * height, (err, height)
    return err


@pytest.mark.parametrize("name", FILES)
def test_shared_bvh_round_trip(name, tmp_path):
    rig = load_bvh(shared(name), scale=0.01)
    out = tmp_path / "out.bvh"
    rig.save(out)
    back = load_bvh(out, scale=0.01)
    clip = rig.clips["take"]
    times, dt = bvh_frame_times(clip)
    keys = clip.tracks[(rig.skeleton.names[0], "rotation")].times
    assert np.isclose(dt, clip.duration / (len(keys) - 1))
    assert_same_motion(rig, clip, back, times)
    # same End Sites
    assert np.allclose(np.nan_to_num(back.skeleton.tails), np.nan_to_num(rig.skeleton.tails),
                       atol=1e-7)


@pytest.mark.parametrize("character,clip_name", [("humanoid", "walk"), ("quadruped", "run")])
def test_bundled_character_clip_round_trip(character, clip_name, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig = rigedit.load_rig(character)
    out = tmp_path / "x.bvh"
    rigedit.save_rig(rig, out, clips=[clip_name])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        back = rigedit.load_rig(out)  # centimetres written, guessed back
    assert any("centimetres" in str(w.message) for w in caught) or character == "quadruped"
    back = load_bvh(out, scale=0.01)
    clip = rig.clips[clip_name]
    assert_same_motion(rig, clip, back, bvh_frame_times(clip)[0])


def test_rest_rotations_scale_and_translation_keys_are_folded(tmp_path):
    """Non-identity rest rotations, a non-unit rest scale and a translation track on a
    non-root joint: none of them exists in BVH, the positions must still come back."""
    sk0 = chain_skeleton(4)
    rest_rot = euler_to_quat([[0, 0, 30], [10, 0, 0], [0, 45, 20], [0, 0, -15]], degrees=True)
    scale = np.ones((4, 3))
    scale[1] = [1.5, 1.5, 1.5]
    sk = Skeleton(sk0.names, sk0.parents, sk0.rest_translation, rest_rot, scale,
                  tails=sk0.tails)
    q = euler_to_quat([[0, 0, 0], [40, 10, 0], [0, 0, 0]], degrees=True)
    tracks = {("j1", "rotation"): Track("rotation", [0, .5, 1], q),
              ("j2", "translation"): Track("translation", [0, 1], [[0, 1, 0], [0.3, 1.2, 0]]),
              ("j0", "translation"): Track("translation", [0, .25, .5, .75, 1],
                                          [[0, 0, 0], [0, .1, 0], [0, 0, 0], [0, .1, 0],
                                           [0, 0, 0]])}
    clip = Clip("bend", sk, tracks)
    rig = Rig(sk, np.zeros((0, 3)), np.zeros((0, 3), int), np.zeros((0, 1), int),
              np.zeros((0, 1)), {"bend": clip})
    out = tmp_path / "bend.bvh"
    info = save_bvh(rig, out)
    assert info == {"clip": "bend", "frames": 5, "frame_time": 0.25}
    text = out.read_text()
    assert "CHANNELS 6" in text.split("JOINT j2")[1].split("JOINT")[0]  # j2's translation keys
    assert "CHANNELS 3" in text.split("JOINT j1")[1].split("JOINT")[0]
    back = load_bvh(out, scale=0.01)
    err = assert_same_motion(rig, clip, back, np.arange(5) * 0.25)
    assert err < 1e-7
    # irregular keys: sampled at 30 fps
    clip2 = Clip("odd", sk, {("j1", "rotation"): Track("rotation", [0, .31, 1], q)})
    times, dt = bvh_frame_times(clip2)
    assert dt == pytest.approx(1 / 30) and len(times) == 31


def test_cli_export_bvh_and_atomicity(tmp_path, capsys, monkeypatch):
    src = shared(FILES[1])
    rig = load_bvh(src, scale=0.01)
    out = tmp_path / "walk.bvh"
    assert main(["export", str(src), "--scale", "0.01", "-o", str(out), "--clip", "take"]) == 0
    assert "clips: take" in capsys.readouterr().out
    back = load_bvh(out, scale=0.01)
    clip = rig.clips["take"]
    assert_same_motion(rig, clip, back, bvh_frame_times(clip)[0])
    # a failing write leaves the old file and no temporary beside it
    before = out.read_bytes()
    def broken(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(np, "savetxt", broken)
    with pytest.raises(OSError, match="disk full"):
        save_bvh(rig, out)
    assert out.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["walk.bvh"]


def test_meshless_rig_folder_round_trip(tmp_path):
    """A BVH rig saved as a rig folder has no mesh or weights file and opens again."""
    rig = load_bvh(shared(FILES[1]), scale=0.01)
    folder = tmp_path / "walk"
    rig.save(folder)
    assert not (folder / "mesh.obj").exists() and not (folder / "weights.npz").exists()
    with warnings.catch_warnings():
        warnings.simplefilter("error")   # no "weights computed" warning: there is no mesh
        back = rigedit.load_rig(folder)
    assert back.vertices.shape == (0, 3) and back.faces.shape == (0, 3)
    clip = rig.clips["take"]
    times = bvh_frame_times(clip)[0]
    np.testing.assert_allclose(positions_per_frame(back, back.clips["take"], times),
                               positions_per_frame(rig, clip, times), atol=1e-6)


def test_source_rotation_orders_are_kept(tmp_path):
    src = shared(FILES[0])   # CMU: Zrotation Yrotation Xrotation, some Zrotation Xrotation Y...
    rig = load_bvh(src, scale=0.01)
    source_lines = [line.split()[-3:] for line in src.read_text().splitlines()
                    if "CHANNELS" in line]
    out = tmp_path / "cmu.bvh"
    rig.save(out)
    written = [line.split()[-3:] for line in out.read_text().splitlines() if "CHANNELS" in line]
    assert written == source_lines and len({tuple(x) for x in written}) == 2
    save_bvh(rig, out, order="XYZ")
    text = out.read_text().split("MOTION")[0]
    assert text.count("Xrotation Yrotation Zrotation") == 31
    back = load_bvh(out, scale=0.01)
    clip = rig.clips["take"]
    assert_same_motion(rig, clip, back, bvh_frame_times(clip)[0])


SHARED_BVH = sorted(str(p.relative_to(DATA)) for p in DATA.glob("**/*.bvh"))


def _guessed(path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rig = load_bvh(path)
    return rig, [str(w.message) for w in caught]


@pytest.mark.parametrize("name", SHARED_BVH)
def test_round_trip_with_guessed_units_keeps_the_size(name, tmp_path):
    """Read with the unit guessed, written (centimetres), read again with the unit guessed:
    the same joint positions in metres (the issue: a carrier-root walk came back 8.5 times
    its size)."""
    rig, _ = _guessed(shared(name))
    out = tmp_path / "out.bvh"
    with warnings.catch_warnings():
        warnings.simplefilter("error")   # a human's size: no warning on writing
        save_bvh(rig, out)
    back, said = _guessed(out)
    assert "guessed centimetres" in said[0] and "NOT SURE" not in said[0], said
    clip = rig.clips["take"]
    assert_same_motion(rig, clip, back, bvh_frame_times(clip)[0])


def test_round_trip_of_a_carrier_root_figure(tmp_path):
    """A carrier root at the origin, the figure 5.4 m from it, written in millimetres: read,
    written, read again, all with guessed units, the size is kept."""
    src = tmp_path / "far.bvh"
    src.write_text(humanoid_bvh(carrier="joint_Root", start=(0, 0, -540), unit=10.0))
    rig, said = _guessed(src)
    assert "guessed millimetres" in said[0]
    out = tmp_path / "back.bvh"
    save_bvh(rig, out)
    back, said = _guessed(out)
    assert "guessed centimetres" in said[0] and "carrier root joint_Root" in said[0]
    clip = rig.clips["take"]
    assert_same_motion(rig, clip, back, bvh_frame_times(clip)[0])
    assert not back.skeleton.deform[back.skeleton.joint_index("joint_Root")]


def test_writing_a_figure_that_is_not_human_sized_warns(tmp_path):
    rig = rigedit.load_rig("quadruped")   # made four times its size below
    sk = rig.skeleton
    big = Skeleton(sk.names, sk.parents, sk.rest_translation * 4, sk.rest_rotation,
                   tails=sk.tails * 4)
    giant = Rig(big, np.zeros((0, 3)), np.zeros((0, 3), int), np.zeros((0, 1), int),
                np.zeros((0, 1)), {})
    with pytest.warns(UserWarning, match="not a human's 1.2-2.2 m: read it back with "
                                         "scale=0.01"):
        save_bvh(giant, tmp_path / "giant.bvh")


def test_keys_nudged_together_are_not_taken_for_a_capture_rate(tmp_path):
    # keys at 30 fps frames and one stopped 1e-4 s from its neighbour (a graph drag): every
    # key on a 1e-4 s grid, which is no frame rate (2 s would be 20,001 BVH frames)
    sk = Skeleton(["a", "b"], [-1, 0], [[0, 0, 0], [0, 1, 0]])
    t = np.array([0.0, 0.3, 0.2999, 1.0, 2.0])
    q = np.tile([0.0, 0.0, 0.0, 1.0], (5, 1))
    clip = Clip("take", sk, {("b", "rotation"): Track("rotation", t, q)}, duration=2.0)
    times, dt = bvh_frame_times(clip)
    assert dt == pytest.approx(1 / 30) and len(times) == 61
    # and the writer says the off-frame key is sampled, in one warning naming the file
    rig = Rig(sk, np.zeros((0, 3)), np.zeros((0, 3), int), np.zeros((0, 1), int),
              np.zeros((0, 1)), {"take": clip})
    with pytest.warns(BvhFramesWarning, match=r"nudged.bvh: 1 of 5 key times fall between "
                                               r"the 30 fps"):
        save_bvh(rig, tmp_path / "nudged.bvh", units_per_metre=1.0)
    # a real 120 Hz capture keeps its rate
    t120 = np.arange(241) / 120.0
    clip = Clip("take", sk, {("b", "rotation"): Track("rotation", t120, np.tile(q[:1], (241, 1)))})
    assert bvh_frame_times(clip)[1] == pytest.approx(1 / 120)
