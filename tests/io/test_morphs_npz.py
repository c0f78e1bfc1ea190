"""Morph targets in rig folders (morphs.npz): saved with the mesh, read back exactly as the
mesh's vertices are, checked before anything is allocated; and a mesh with vertices no face
uses saves to a folder that loads back."""
import numpy as np
import pytest

import rigedit
from morph_builders import quadruped_with_targets
from rigedit.errors import RigFileError
from rigedit.io.morphs_npz import MAX_TARGETS, load_morphs, save_morphs
from rigedit.model.morph import MorphTargets


def test_a_rig_folder_keeps_the_targets_and_their_weight_tracks(tmp_path):
    rig = quadruped_with_targets()
    clip = rig.clips["walk"]
    clip.set_morph_key("bulge", 0.25, 0.8)
    rigedit.save_rig(rig, tmp_path / "q")
    back = rigedit.load_rig(tmp_path / "q")
    assert back.morphs.names == rig.morphs.names
    np.testing.assert_array_equal(back.morphs.deltas, rig.morphs.deltas)
    assert sorted(back.clips["walk"].morph_tracks) == ["bulge"]
    pose = clip.sample(0.25)
    weights = {"bulge": 0.8, "squash": 0.3}
    moved = back.skin(back.clips["walk"].sample(0.25), morph_weights=weights)
    np.testing.assert_allclose(moved, rig.skin(pose, morph_weights=weights), atol=1e-5)
    assert np.abs(moved - back.skin(pose)).max() > 1e-3   # the targets do move the skin


def test_a_rig_without_targets_writes_no_morph_file(tmp_path):
    rigedit.save_rig(rigedit.load_rig("quadruped"), tmp_path / "q")
    assert not (tmp_path / "q" / "morphs.npz").exists()
    assert rigedit.load_rig(tmp_path / "q").morphs is None


def test_vertices_no_face_uses_are_left_out_and_the_folder_loads(tmp_path):
    rig = quadruped_with_targets()
    stray = np.array([[9.0, 9.0, 9.0], [-9.0, 9.0, 9.0]])
    data = rig.data()
    data.vertices = np.vstack([data.vertices, stray])
    data.indices = np.vstack([data.indices, data.indices[:2]])
    data.weights = np.vstack([data.weights, data.weights[:2]])
    data.morphs = MorphTargets(rig.morphs.names,
                               np.concatenate([rig.morphs.deltas,
                                               np.ones((2, 2, 3), np.float32)], axis=1))
    rigedit.save_rig(data, tmp_path / "q")
    back = rigedit.load_rig(tmp_path / "q")
    assert len(back.vertices) == len(rig.vertices)
    np.testing.assert_allclose(back.vertices, rig.vertices, atol=1e-6)
    np.testing.assert_array_equal(back.morphs.deltas, rig.morphs.deltas)


@pytest.mark.parametrize("arrays, problem", [
    ({"deltas": np.zeros((1, 4, 3), np.float32)}, "missing 'names'"),
    ({"names": np.array(["a"]), "deltas": np.zeros((1, 5, 3), np.float32)}, "shape (1, 4, 3)"),
    ({"names": np.array(["a", "b"]), "deltas": np.zeros((1, 4, 3), np.float32)},
     "shape (2, 4, 3)"),
    ({"names": np.array(["a"]), "deltas": np.zeros((1, 4, 3), np.int32)}, "in floats"),
    ({"names": np.array(["a", "a"]), "deltas": np.zeros((2, 4, 3), np.float32)}, "unique"),
    ({"names": np.array(["a"]), "deltas": np.full((1, 4, 3), np.nan, np.float32)}, "finite"),
    ({"names": np.array(["a"]), "deltas": np.zeros((1, 4, 3), np.float32),
      "default_weights": np.zeros(3)}, "'default_weights' of shape (1,)"),
    ({"names": np.array([], dtype=str), "deltas": np.zeros((0, 4, 3), np.float32)},
     f"1 to {MAX_TARGETS} targets"),
])
def test_a_malformed_morph_file_is_one_error_naming_it(tmp_path, arrays, problem):
    path = tmp_path / "morphs.npz"
    np.savez(path, **arrays)
    with pytest.raises(RigFileError) as err:
        load_morphs(path, 4)
    assert str(path) in str(err.value) and problem in str(err.value)


def test_save_and_load_give_the_same_targets(tmp_path):
    rng = np.random.default_rng(3)
    targets = MorphTargets(("a", "b"), rng.normal(size=(2, 6, 3)).astype(np.float32),
                           normal_deltas=rng.normal(size=(2, 6, 3)).astype(np.float32),
                           default_weights=np.array([0.25, 0.0]))
    save_morphs(tmp_path / "m.npz", targets)
    back = load_morphs(tmp_path / "m.npz", 6)
    assert back.names == ("a", "b")
    np.testing.assert_array_equal(back.deltas, targets.deltas)
    np.testing.assert_array_equal(back.normal_deltas, targets.normal_deltas)
    np.testing.assert_array_equal(back.default_weights, targets.default_weights)
