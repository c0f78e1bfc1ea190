import json
import warnings

import numpy as np
import pytest

from builders import cylinder_rig, write_elk_folder
from rigedit.errors import RigFileError
from rigedit.io import (UnknownJointsWarning, WeightsComputedWarning, atomic_write, load_clip,
                        load_rig_folder, load_skeleton, load_weights, save_clip,
                        save_rig_folder, save_weights)


def test_elk_layout_opens_as_is(tmp_path):
    folder = write_elk_folder(tmp_path / "elk")
    with pytest.warns(WeightsComputedWarning, match="no weights file"):
        rig = load_rig_folder(folder)
    assert rig.up == "z"
    assert rig.skeleton.names == ["_rootJoint", "hip", "spine", "head"]
    # Bind matrices are translations to the heads (axis-aligned frames).
    assert np.allclose(rig.skeleton.bind_matrices[2], np.r_[np.c_[np.eye(3), [0, 0, 1.5]],
                                                            [[0, 0, 0, 1]]])
    assert not rig.skeleton.deform[0]  # the zero-length root takes no weights
    assert rig.binding.indices.max() > 0 and 0 not in set(rig.binding.indices[rig.binding.weights > 0])
    assert len(rig.vertices) == 31 * 24 + 2  # seam duplicates welded


def test_elk_clip_semantics_rz_ry_rx_at_head(tmp_path):
    folder = write_elk_folder(tmp_path / "elk")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", WeightsComputedWarning)
        rig = load_rig_folder(folder)
    clip = rig.clips["bow"]
    assert clip.duration == 1.0
    pose = clip.sample(1.0)
    m = rig.joint_matrices(pose)
    # spine rotated 0.5 rad about X at its head (0, 0, 1.5): head joint swings in the YZ plane
    assert np.allclose(m[2, :3, 3], [0, 0, 1.5])
    assert np.allclose(m[3, :3, 3], [0, -np.sin(0.5), 1.5 + np.cos(0.5)])
    half = rig.joint_matrices(clip.sample(0.5))
    assert np.allclose(half[3, :3, 3], [0, -np.sin(0.25), 1.5 + np.cos(0.25)])


def test_clip_naming_unknown_joints_warns_once_and_loads_the_rest(tmp_path):
    folder = write_elk_folder(tmp_path / "elk", extra_clip_joints=("antler_L", "antler_R"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rig = load_rig_folder(folder)
    unknown = [w for w in caught if issubclass(w.category, UnknownJointsWarning)]
    assert len(unknown) == 1 and "antler_L, antler_R" in str(unknown[0].message)
    assert ("spine", "rotation") in rig.clips["bow"].tracks


def test_rig_folder_round_trip(tmp_path):
    rig = cylinder_rig()
    save_rig_folder(tmp_path / "r", rig)
    back = load_rig_folder(tmp_path / "r")
    assert back.skeleton.names == rig.skeleton.names
    assert np.allclose(back.vertices, rig.vertices, atol=1e-6)
    assert np.allclose(back.binding.dense(), rig.binding.dense(), atol=1e-6)
    pose_a, pose_b = rig.clips["bend"].sample(0.3), back.clips["bend"].sample(0.3)
    assert pose_a.allclose(pose_b, atol=1e-8)
    assert not back.weights_computed


@pytest.mark.parametrize("content,msg", [
    ("{", "malformed JSON at line 1"),
    ('{"joints": []}', "expected at least one joint"),
    ('{"joints": [{"name": "a", "parent": "b"}]}', "joint 'a' has unknown parent 'b'"),
    ('{"joints": [{"name": "a", "translation": [1, 2]}]}', "joint 'a': expected 'translation'"),
    ('{"joints": [{"name": "a", "head": [0, 0, 0], "tail": [0, 0, 1], "parent": null},'
     ' {"name": "a", "head": [0, 0, 1], "parent": "a"}]}', "duplicate joint name 'a'"),
    ('[1, 2]', "expected a JSON object"),
])
def test_bad_skeleton_files(tmp_path, content, msg):
    p = tmp_path / "skeleton.json"
    p.write_text(content)
    with pytest.raises(RigFileError, match=msg) as err:
        load_skeleton(p)
    assert str(p) in str(err.value)


@pytest.mark.parametrize("content,msg", [
    ('{"name": "x"}', "expected a clip with 'tracks'"),
    ('{"tracks": [{"joint": "j1", "channel": "spin", "times": [0], "values": [[0]]}]}',
     "expected 'channel' to be one of"),
    ('{"tracks": [{"joint": "j1", "channel": "rotation", "times": [0, 1], '
     '"values": [[0, 0, 0, 1]]}]}', r"'values' to be a list of 2 rows of 4 numbers"),
    ('{"tracks": [{"joint": "j1", "channel": "translation", "times": [0, 0], '
     '"values": [[0, 0, 0], [1, 1, 1]]}]}', "two keys at time 0"),
    ('{"keyframes": {"j1": [{"rotation": [0, 0, 0]}]}}', "expected a 'time' field"),
])
def test_bad_clip_files(tmp_path, content, msg):
    rig = cylinder_rig(with_clip=False)
    p = tmp_path / "clip.json"
    p.write_text(content)
    with pytest.raises(RigFileError, match=msg) as err:
        load_clip(p, rig.skeleton)
    assert str(p) in str(err.value)


def test_clip_round_trip_keeps_interpolation_and_loop(tmp_path):
    rig = cylinder_rig()
    clip = rig.clips["bend"]
    clip.loop = False
    save_clip(tmp_path / "bend.json", clip)
    back = load_clip(tmp_path / "bend.json", rig.skeleton)
    assert back.loop is False and back.duration == clip.duration
    assert back.tracks[("j1", "rotation")].interpolation == "slerp"
    assert json.loads((tmp_path / "bend.json").read_text())["format"] == "rigedit.clip"


def test_weights_file_errors(tmp_path):
    rig = cylinder_rig(with_clip=False)
    n = len(rig.vertices)
    p = tmp_path / "w.npz"
    save_weights(p, rig.binding.indices, rig.binding.weights, rig.skeleton.names)
    idx, w = load_weights(p, rig.skeleton, n)
    assert np.array_equal(idx, rig.binding.indices)
    with pytest.raises(RigFileError, match=f"expected weights for {n + 1} vertices"):
        load_weights(p, rig.skeleton, n + 1)
    save_weights(p, rig.binding.indices, rig.binding.weights, ["a", "b", "c"])
    with pytest.raises(RigFileError, match="weights name joints the skeleton lacks"):
        load_weights(p, rig.skeleton, n)
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    with pytest.raises(RigFileError, match="junk.npz"):
        load_weights(tmp_path / "junk.npz", rig.skeleton, n)


def test_weights_are_remapped_by_joint_name(tmp_path):
    rig = cylinder_rig(with_clip=False)
    names = rig.skeleton.names[::-1]
    remap = {n: i for i, n in enumerate(names)}
    idx = np.array([[remap[rig.skeleton.names[j]] for j in row] for row in rig.binding.indices])
    save_weights(tmp_path / "w.npz", idx, rig.binding.weights, names)
    back, _ = load_weights(tmp_path / "w.npz", rig.skeleton, len(rig.vertices))
    assert np.array_equal(back, rig.binding.indices)


def test_missing_pieces_of_a_rig_folder(tmp_path):
    with pytest.raises(RigFileError, match="expected a mesh file"):
        load_rig_folder(tmp_path)
    (tmp_path / "m.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(RigFileError, match="expected skeleton.json"):
        load_rig_folder(tmp_path)


def test_atomic_write_keeps_the_old_file_on_failure(tmp_path):
    p = tmp_path / "keep.json"
    p.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_write(p) as fh:
            fh.write("half-writ")
            raise RuntimeError("crash mid-write")
    assert p.read_text() == "old"
    assert [x.name for x in tmp_path.iterdir()] == ["keep.json"]


def test_round_trip_keeps_coincident_vertices(tmp_path):
    """A mesh with two vertices at one position (split normals) keeps its vertex count, so
    its weights still fit after save and load."""
    rig = cylinder_rig(with_clip=False)
    from rigedit.rig import Rig

    dup = np.vstack([rig.vertices, rig.vertices[:1]])
    faces = rig.faces.copy()
    first = np.flatnonzero((faces == 0).any(axis=1))[0]
    faces[first][faces[first] == 0] = len(dup) - 1
    twin = Rig(rig.skeleton, dup, faces, name="twin")
    save_rig_folder(tmp_path / "t", twin)
    back = load_rig_folder(tmp_path / "t")
    assert len(back.vertices) == len(dup)
    assert np.allclose(back.binding.dense(), twin.binding.dense(), atol=1e-6)


def test_atomic_write_gives_normal_file_permissions(tmp_path):
    import os

    umask = os.umask(0o022)
    try:
        with atomic_write(tmp_path / "new.json") as fh:
            fh.write("{}")
        assert (tmp_path / "new.json").stat().st_mode & 0o777 == 0o644
        (tmp_path / "old.json").write_text("x")
        os.chmod(tmp_path / "old.json", 0o640)
        with atomic_write(tmp_path / "old.json") as fh:
            fh.write("y")
        assert (tmp_path / "old.json").stat().st_mode & 0o777 == 0o640
    finally:
        os.umask(umask)


def test_elk_skeleton_parents_from_hierarchy_when_joints_omit_them(tmp_path):
    p = tmp_path / "skeleton.json"
    p.write_text(json.dumps({
        "joints": [{"name": "b", "head": [0, 0, 1], "tail": [0, 0, 2]},
                   {"name": "a", "head": [0, 0, 0], "tail": [0, 0, 1]}],
        "bones": ["a", "b"], "hierarchy": {"b": "a"}}))
    sk, meta = load_skeleton(p)
    assert meta["format"] == "elk"
    assert sk.names == ["a", "b"] and list(sk.parents) == [-1, 0]
    assert np.allclose(sk.rest_translation[1], [0, 0, 1])
