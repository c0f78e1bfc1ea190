"""IK: FABRIK reaches, keeps lengths, stretches; aiming and chain selection on skeletons."""
import subprocess
import sys

import numpy as np
import pytest

from builders import chain_skeleton
from rigedit.model import Pose
from rigedit.model.ik import aim_joint, drag_joint, fabrik, ik_chain


def _lengths(p):
    return np.linalg.norm(np.diff(p, axis=0), axis=1)


def test_fabrik_reaches_reachable_target_and_keeps_lengths():
    chain = np.array([[0, 0, 0], [0, 1, 0], [0, 2, 0], [0, 3, 0]], dtype=float)
    target = np.array([1.2, 1.5, 0.7])
    out = fabrik(chain, target, tolerance=1e-8, max_iterations=200)
    assert np.linalg.norm(out[-1] - target) < 1e-6
    np.testing.assert_allclose(_lengths(out), 1.0, atol=1e-9)
    np.testing.assert_array_equal(out[0], chain[0])


def test_fabrik_stretches_towards_unreachable_target():
    chain = np.array([[0, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float)
    target = np.array([0.0, 0.0, 10.0])
    out = fabrik(chain, target)
    np.testing.assert_allclose(_lengths(out), 1.0, atol=1e-12)
    np.testing.assert_allclose(out[-1], [0, 0, 2.0], atol=1e-12)  # straight at the target
    np.testing.assert_allclose(out[1], [0, 0, 1.0], atol=1e-12)


def test_fabrik_rejects_single_point():
    with pytest.raises(ValueError, match="expected positions"):
        fabrik(np.zeros((1, 3)), np.ones(3))


@pytest.mark.parametrize("seed", range(5))
def test_fabrik_random_chains(seed):
    rng = np.random.default_rng(seed)
    chain = np.cumsum(rng.normal(size=(5, 3)), axis=0)
    lengths = _lengths(chain)
    direction = rng.normal(size=3)
    target = chain[0] + direction / np.linalg.norm(direction) * 0.6 * lengths.sum()
    out = fabrik(chain, target, tolerance=1e-7, max_iterations=500)
    np.testing.assert_allclose(_lengths(out), lengths, rtol=1e-9)
    assert np.linalg.norm(out[-1] - target) < 1e-5


def _fk(sk, pose):
    return sk.forward(pose.local_matrices())


def test_aim_joint_points_bone_at_target_keeping_length():
    sk = chain_skeleton(3)
    pose = Pose(sk)
    model = _fk(sk, pose)
    target = np.array([1.0, 1.0, 0.0])  # from j1 at (0,1,0): straight along +x
    aim_joint(sk, pose, model, 1, model[2, :3, 3], target)
    new = _fk(sk, pose)
    np.testing.assert_allclose(new[2, :3, 3], [1.0, 1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(new[1, :3, 3], model[1, :3, 3])  # the head stays


def test_aim_joint_under_rotated_parent():
    sk = chain_skeleton(4)
    pose = Pose(sk)
    pose.set_euler(0, [0, 0, 40], degrees=True)
    pose.set_euler(1, [25, 0, 0], degrees=True)
    model = _fk(sk, pose)
    head = model[2, :3, 3]
    target = head + np.array([0.3, -0.2, 0.9])
    aim_joint(sk, pose, model, 2, model[3, :3, 3], target)
    new = _fk(sk, pose)
    d = new[3, :3, 3] - head
    np.testing.assert_allclose(np.linalg.norm(d), 1.0, atol=1e-12)
    np.testing.assert_allclose(d / np.linalg.norm(d), (target - head) / np.linalg.norm(target - head),
                               atol=1e-9)


def test_drag_joint_two_bone_chain_reaches_and_keeps_lengths():
    sk = chain_skeleton(4)
    pose = Pose(sk)
    rest = _fk(sk, pose)
    target = np.array([0.8, 2.2, 0.5])  # distance from j1 (0,1,0) is < 2: reachable
    drag_joint(sk, pose, 3, target, chain_length=2)
    new = _fk(sk, pose)
    np.testing.assert_allclose(new[3, :3, 3], target, atol=1e-5)
    heads = new[:, :3, 3]
    np.testing.assert_allclose(_lengths(heads), 1.0, atol=1e-9)
    np.testing.assert_allclose(heads[:2], rest[:2, :3, 3])  # above the chain: unchanged
    np.testing.assert_array_equal(pose.rotation[0], sk.rest_rotation[0])
    assert not np.allclose(pose.rotation[1], sk.rest_rotation[1])


def test_drag_joint_unreachable_stretches():
    sk = chain_skeleton(3)
    pose = Pose(sk)
    drag_joint(sk, pose, 2, [0.0, 0.0, 10.0], chain_length=1)
    new = _fk(sk, pose)
    d = np.array([0.0, -1.0, 10.0])  # from the parent's head (0, 1, 0) to the target
    np.testing.assert_allclose(new[2, :3, 3], [0, 1, 0] + d / np.linalg.norm(d), atol=1e-12)


def test_drag_root_translates_whole_character():
    sk = chain_skeleton(3)
    pose = Pose(sk)
    drag_joint(sk, pose, 0, [0.5, 0.0, -1.0])
    new = _fk(sk, pose)
    np.testing.assert_allclose(new[:, :3, 3] - _fk(sk, Pose(sk))[:, :3, 3],
                               np.tile([0.5, 0.0, -1.0], (3, 1)), atol=1e-12)


def test_ik_chain_stops_at_root_and_branches():
    from rigedit.io.skeleton_json import skeleton_from_heads

    names = ["root", "hips", "thigh", "shin", "foot", "spine"]
    parents = [None, "root", "hips", "thigh", "shin", "hips"]
    heads = np.array([[0, 0, 0], [0, 1, 0], [0.2, 1, 0], [0.2, 0.5, 0], [0.2, 0, 0], [0, 1.5, 0]])
    sk = skeleton_from_heads(names, parents, heads)
    foot = sk.joint_index("foot")
    assert [sk.names[j] for j in ik_chain(sk, foot, 2)] == ["thigh", "shin"]
    # hips branches (thigh and spine): a long chain stops below it
    assert [sk.names[j] for j in ik_chain(sk, foot, 5)] == ["thigh", "shin"]
    assert [sk.names[j] for j in ik_chain(sk, foot, 1)] == ["shin"]
    assert ik_chain(sk, sk.joint_index("root"), 2) == []
    # the direct parent always takes part, even a branching one
    assert [sk.names[j] for j in ik_chain(sk, sk.joint_index("spine"), 3)] == ["hips"]


def test_ik_imports_no_gui():
    code = ("import sys, rigedit.model.ik\n"
            "print(','.join(m for m in sys.modules if m.split('.')[0] in "
            "('PyQt5', 'vtk', 'vtkmodules', 'pyvista')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == ""
