"""Clip editing (keys inserted, deleted, moved, copied, pasted; interpolation per track; undo
snapshots) and the JSON round trip of every interpolation mode."""
import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from builders import chain_skeleton
from rigedit.animation import Clip, Track
from rigedit.animation.interpolate import ROTATION_MODES, VECTOR_MODES
from rigedit.io.clip_json import load_clip, save_clip
from rigedit.model import Pose


def quat_z(deg):
    return Rotation.from_euler("z", deg, degrees=True).as_quat()


@pytest.fixture
def sk():
    return chain_skeleton(3)


@pytest.fixture
def clip(sk):
    return Clip("bend", sk, {("j1", "rotation"): Track("rotation", [0, 1], [quat_z(0), quat_z(90)]),
                             ("j2", "rotation"): Track("rotation", [0, 0.5], [quat_z(0), quat_z(30)])},
                duration=2.0)


def test_key_pose_keys_rotation_and_only_moved_vector_channels(sk):
    clip = Clip("c", sk, duration=1.0)
    pose = Pose(sk)
    pose.set_rotation("j1", quat_z(45))
    pose.set_translation("j2", [0.5, 1, 0])
    assert clip.key_pose(pose, 0.25) == 4        # 3 rotations + j2's moved translation
    assert set(clip.tracks) == {("j0", "rotation"), ("j1", "rotation"), ("j2", "rotation"),
                                ("j2", "translation")}
    assert clip.sample(0.25).allclose(pose)


def test_key_pose_on_selected_joint_replaces_a_key_at_the_same_time(clip, sk):
    pose = clip.sample(1.0)
    pose.set_rotation("j1", quat_z(-20))
    rev = clip.revision
    clip.key_pose(pose, 1.0, joints=["j1"])
    assert clip.revision > rev
    np.testing.assert_allclose(clip.tracks[("j1", "rotation")].times, [0, 1])
    assert clip.sample(1.0).allclose(pose)


def test_delete_keys_removes_emptied_tracks(clip):
    assert clip.delete_keys([0.5]) == 1
    assert len(clip.tracks[("j2", "rotation")]) == 1
    assert clip.delete_keys([0.0], joints=["j2"]) == 1
    assert ("j2", "rotation") not in clip.tracks
    assert clip.delete_keys([0.77]) == 0


def test_move_keys_shifts_the_pose_in_time(clip):
    before = clip.sample(1.0)
    clip.move_keys({1.0: 1.5}, joints=["j1"])
    np.testing.assert_allclose(clip.tracks[("j1", "rotation")].times, [0, 1.5])
    assert clip.sample(1.5).allclose(before)
    assert not clip.sample(1.0).allclose(before)
    with pytest.raises(ValueError, match=">= 0"):
        clip.move_keys({0.0: -1.0})


def test_move_key_onto_another_replaces_it(clip):
    clip.move_keys({0.0: 1.0}, joints=["j1"])
    tr = clip.tracks[("j1", "rotation")]
    assert len(tr) == 1 and tr.times[0] == 1.0
    np.testing.assert_allclose(abs(np.dot(tr.values[0], quat_z(0))), 1.0)


def test_copy_paste_keys_duplicates_a_pose(clip):
    data = clip.copy_keys(1.0)
    clip.paste_keys(data, 1.8)
    assert clip.sample(1.8).allclose(clip.sample(1.0))
    assert 1.8 in clip.key_times("j1")


def test_set_interpolation_per_track_and_validation(clip):
    clip.set_interpolation("catmull_rom", joint="j1", channel="rotation")
    assert clip.tracks[("j1", "rotation")].interpolation == "catmull_rom"
    assert clip.tracks[("j2", "rotation")].interpolation == "slerp"
    clip.set_key("j1", "translation", 0.0, [0, 1, 0])
    with pytest.raises(ValueError, match="interpolation"):
        clip.set_interpolation("hybrid")          # translation has no hybrid
    assert clip.tracks[("j2", "rotation")].interpolation == "slerp"    # nothing changed


def test_state_restore_is_an_undo(clip):
    state = clip.state()
    before = clip.sample(0.7)
    clip.delete_keys([1.0])
    clip.set_duration(5.0)
    assert not clip.sample(0.7).allclose(before)
    clip.restore(state)
    assert clip.sample(0.7).allclose(before) and clip.duration == 2.0


def test_duration_validated(clip):
    with pytest.raises(ValueError, match="duration"):
        clip.set_duration(0)


@pytest.mark.parametrize("channel,mode", [("rotation", m) for m in ROTATION_MODES]
                         + [("translation", m) for m in VECTOR_MODES])
def test_json_round_trip_keeps_interpolation(tmp_path, sk, channel, mode):
    rng = np.random.default_rng(1)
    times = [0.0, 0.3, 0.9, 1.4]
    values = (np.stack([quat_z(a) for a in (0, 40, 100, 130)]) if channel == "rotation"
              else rng.normal(size=(4, 3)))
    clip = Clip("walk", sk, {("j1", channel): Track(channel, times, values, mode)},
                duration=1.5, loop=False)
    save_clip(tmp_path / "walk.json", clip)
    data = json.loads((tmp_path / "walk.json").read_text())
    assert data["tracks"][0]["interpolation"] == mode
    back = load_clip(tmp_path / "walk.json", sk)
    assert back.tracks[("j1", channel)].interpolation == mode
    assert back.duration == 1.5 and back.loop is False
    for t in np.linspace(0, 1.5, 11):
        assert back.sample(t).allclose(clip.sample(t), atol=1e-8)


def test_save_is_atomic_on_failure(tmp_path, clip, monkeypatch):
    path = tmp_path / "c.json"
    save_clip(path, clip)
    before = path.read_text()
    import rigedit.io.atomic as atomic

    def boom(*a, **k):
        raise RuntimeError("disk full")
    monkeypatch.setattr(atomic.json, "dump", boom)
    with pytest.raises(RuntimeError):
        save_clip(path, clip)
    assert path.read_text() == before
    assert [p.name for p in tmp_path.iterdir()] == ["c.json"]
