import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from builders import chain_skeleton
from rigedit.model import Pose, SkinBinding, Skeleton, local_to_model, skinning_matrices
from rigedit.model.skinning import top_k_influences


def naive_skin(rest, dense_w, palette):
    out = np.zeros_like(rest)
    for v in range(len(rest)):
        m = sum(dense_w[v, j] * palette[j] for j in range(len(palette)))
        out[v] = (m @ np.r_[rest[v], 1.0])[:3]
    return out


def test_rest_pose_skins_to_rest_mesh(cyl_rig):
    assert np.allclose(cyl_rig.skin(cyl_rig.rest_pose()), cyl_rig.vertices, atol=1e-5)


def test_vertex_fully_weighted_to_one_joint_moves_rigidly():
    sk = chain_skeleton(3)
    rest = np.array([[0.2, 1.5, 0.1], [0.0, 2.5, 0.3], [0.1, 0.2, 0.0]])
    binding = SkinBinding(rest, [[1, 0], [2, 0], [0, 1]], [[1, 0], [1, 0], [1, 0]], 3)
    pose = Pose(sk)
    pose.set_euler("j1", [10, 20, 30], degrees=True)
    pose.set_translation("j0", [1, 2, 3])
    m = local_to_model(sk, pose)
    out = binding.skin(skinning_matrices(sk, m))
    for v, j in enumerate([1, 2, 0]):
        local = sk.inverse_bind_matrices[j] @ np.r_[rest[v], 1]
        assert np.allclose(out[v], (m[j] @ local)[:3], atol=1e-5)


@pytest.mark.parametrize("k", [1, 4, 8])
def test_random_poses_match_naive_per_vertex_reference(k):
    rng = np.random.default_rng(k)
    n = 12
    parents = np.array([-1] + [int(rng.integers(0, j)) for j in range(1, n)])
    sk = Skeleton([f"j{i}" for i in range(n)], parents, rng.normal(size=(n, 3)))
    rest = rng.normal(size=(60, 3))
    idx, w = top_k_influences(rng.random((60, n)), k)
    binding = SkinBinding(rest, idx, w, n)
    for trial in range(3):
        pose = Pose(sk, rng.normal(size=(n, 3)), Rotation.random(n, random_state=trial).as_quat(),
                    rng.uniform(0.5, 1.5, size=(n, 3)))
        palette = skinning_matrices(sk, local_to_model(sk, pose))
        ref = naive_skin(rest, binding.dense(), palette)
        assert np.allclose(binding.skin(palette), ref, atol=1e-4)


def test_top_k_keeps_largest_and_normalises():
    w = np.array([[0.1, 0.5, 0.2, 0.0, 0.2], [0, 0, 0, 0, 0]])
    idx, val = top_k_influences(w, 2)
    assert list(idx[0]) == [1, 2] or list(idx[0]) == [1, 4]
    assert np.allclose(val.sum(axis=1), 1.0)
    assert np.isclose(val[0, 0], 0.5 / 0.7)
    assert val[1, 0] == 1.0  # a vertex with no weight is given to one joint, not lost


def test_binding_rejects_bad_input():
    with pytest.raises(ValueError, match="joint indices"):
        SkinBinding(np.zeros((2, 3)), [[0], [5]], [[1], [1]], 3)
    with pytest.raises(ValueError, match="vertex 1 has no weight"):
        SkinBinding(np.zeros((2, 3)), [[0], [1]], [[1], [0]], 3)


def test_rig_weights_are_sparse_rows_summing_to_one(cyl_rig):
    w = cyl_rig.weights
    assert w.shape == (len(cyl_rig.vertices), len(cyl_rig.skeleton))
    assert np.allclose(np.asarray(w.sum(axis=1)).ravel(), 1.0, atol=1e-6)


def test_bending_the_middle_joint_moves_only_the_upper_part(cyl_rig):
    y = cyl_rig.vertices[:, 1]
    # Rigid binding by height: j0 below y=1, j1 up to 2, j2 above.
    idx = np.clip(np.floor(y), 0, 2).astype(int)[:, None]
    cyl_rig.bind(idx, np.ones_like(idx, dtype=float))
    pose = cyl_rig.rest_pose()
    pose.set_euler("j1", [0, 0, 60], degrees=True)
    moved = np.linalg.norm(cyl_rig.skin(pose) - cyl_rig.vertices, axis=1)
    assert moved[y < 1.0].max() < 1e-6        # bound to j0 only
    assert moved[y > 2.5].min() > 0.5         # the top swings with j1
