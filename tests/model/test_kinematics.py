import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from builders import chain_skeleton
from rigedit.model import Pose, Skeleton, local_to_model, skinning_matrices


def rz(deg):
    a = np.radians(deg)
    m = np.eye(4)
    m[:2, :2] = [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]
    return m


def tr(x, y, z):
    m = np.eye(4)
    m[:3, 3] = [x, y, z]
    return m


def test_chain_fk_matches_hand_computed_matrices():
    sk = chain_skeleton(3)
    pose = Pose(sk)
    pose.set_euler("j0", [0, 0, 90], degrees=True)
    pose.set_euler("j1", [0, 0, -90], degrees=True)
    m = local_to_model(sk, pose)
    assert np.allclose(m[0], rz(90))
    assert np.allclose(m[1], rz(90) @ tr(0, 1, 0) @ rz(-90))
    assert np.allclose(m[2], rz(90) @ tr(0, 1, 0) @ rz(-90) @ tr(0, 1, 0))
    # j1 sits at (-1, 0, 0) after the 90 degree turn; j1's -90 undoes it, so j2 is one unit
    # above j1.
    assert np.allclose(m[1, :3, 3], [-1, 0, 0]) and np.allclose(m[2, :3, 3], [-1, 1, 0])


def test_translation_and_scale_channels():
    sk = chain_skeleton(2)
    pose = Pose(sk)
    pose.set_translation("j0", [5, 0, 0])
    pose.set_scale("j0", [2, 2, 2])
    m = local_to_model(sk, pose)
    assert np.allclose(m[1, :3, 3], [5, 2, 0])
    assert np.allclose(skinning_matrices(sk, m)[0][:3, 3], [5, 0, 0])


def naive_fk(parents, local):
    out = []
    for j, p in enumerate(parents):
        out.append(local[j] if p < 0 else out[p] @ local[j])
    return np.array(out)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 100_000), st.integers(1, 30))
def test_random_trees_match_naive_per_joint_fk(seed, n):
    rng = np.random.default_rng(seed)
    parents = np.array([-1] + [int(rng.integers(-1, j)) for j in range(1, n)])
    sk = Skeleton([f"j{i}" for i in range(n)], parents, rng.normal(size=(n, 3)),
                  Rotation.random(n, random_state=seed).as_quat())
    pose = Pose(sk, rng.normal(size=(n, 3)), Rotation.random(n, random_state=seed + 1).as_quat(),
                rng.uniform(0.5, 2, size=(n, 3)))
    assert np.allclose(local_to_model(sk, pose), naive_fk(parents, pose.local_matrices()))


def test_set_euler_is_relative_to_rest_orientation():
    rest_q = Rotation.from_euler("z", 45, degrees=True).as_quat()
    sk = Skeleton(["a"], [-1], [[0, 0, 0]], [rest_q])
    pose = Pose(sk)
    pose.set_euler("a", [0, 0, 45], degrees=True)
    assert np.allclose(Rotation.from_quat(pose.rotation[0]).as_euler("xyz", degrees=True),
                       [0, 0, 90])
    assert np.allclose(pose.get_euler("a", degrees=True), [0, 0, 45])
