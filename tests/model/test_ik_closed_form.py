"""The fast IK path against the iterative solver it replaced.

The reference below is the module as it was before the closed form: FABRIK on numpy rows and
``np.linalg.norm``, SciPy ``Rotation`` objects per aim, and the whole skeleton's forward
kinematics recomputed before each chain joint. Run to a tight tolerance, FABRIK converges to
the two-bone solution, so the closed form must agree with it; the rest checks what a drag must
keep (bone lengths, twist) and that degenerate targets and bones give finite poses.
"""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from builders import chain_skeleton
from rigedit.model import Pose, Skeleton
from rigedit.model.ik import drag_joint, fabrik, solve_chain, two_bone
from rigedit.model.kinematics import local_to_model


# ---------------------------------------------------------------------- the old solver
def _unit(v):
    n = np.linalg.norm(v)
    return v / n if n > 1e-12 else np.array([0.0, 1.0, 0.0])


def reference_fabrik(positions, target, tolerance=1e-6, max_iterations=30):
    p = np.array(positions, dtype=np.float64)
    target = np.asarray(target, dtype=np.float64)
    lengths = np.linalg.norm(np.diff(p, axis=0), axis=1)
    base = p[0].copy()
    dist = np.linalg.norm(target - base)
    if dist >= lengths.sum():
        direction = (target - base) / dist if dist > 1e-12 else _unit(p[-1] - p[0])
        p[1:] = base + np.cumsum(lengths)[:, None] * direction
        return p
    for _ in range(max_iterations):
        if np.linalg.norm(p[-1] - target) <= tolerance:
            break
        p[-1] = target
        for i in range(len(p) - 2, -1, -1):
            p[i] = p[i + 1] + _unit(p[i] - p[i + 1]) * lengths[i]
        p[0] = base
        for i in range(1, len(p)):
            p[i] = p[i - 1] + _unit(p[i] - p[i - 1]) * lengths[i - 1]
    return p


def _reference_rotation_between(a, b):
    a, b = _unit(a), _unit(b)
    axis = np.cross(a, b)
    s, c = np.linalg.norm(axis), float(np.dot(a, b))
    if s < 1e-12:
        return Rotation.identity()   # the tests below never ask for a half turn
    return Rotation.from_rotvec(axis / s * np.arctan2(s, c))


def reference_solve_chain(sk, pose, chain, end, target, tolerance=1e-13, max_iterations=200000):
    """The old ``solve_chain``, FABRIK run to ``tolerance`` (the editor's was 1e-6)."""
    model = local_to_model(sk, pose)
    points = np.vstack([model[chain, :3, 3], model[end, :3, 3]])
    solved = reference_fabrik(points, target, tolerance, max_iterations)
    for k, j in enumerate(chain):
        model = local_to_model(sk, pose)
        nxt = chain[k + 1] if k + 1 < len(chain) else end
        head = model[j, :3, 3]
        delta = _reference_rotation_between(model[nxt, :3, 3] - head, solved[k + 1] - head)
        parent = sk.parents[j]
        if parent >= 0:
            lin = model[parent, :3, :3]
            rp = Rotation.from_matrix(lin / np.linalg.norm(lin, axis=0, keepdims=True))
            delta = rp.inv() * delta * rp
        pose.rotation[j] = (delta * Rotation.from_quat(pose.rotation[j])).as_quat()
    return solved


# ---------------------------------------------------------------------- helpers
def _lengths(p):
    return np.linalg.norm(np.diff(p, axis=0), axis=1)


def _reachable_target(rng, points, margin=0.05):
    """A target whose distance from the base is inside the chain's reach by ``margin`` of
    its length at both ends (FABRIK converges slowly at the boundary)."""
    l1, l2 = _lengths(points)
    lo, hi = abs(l1 - l2) + margin * (l1 + l2), (1 - margin) * (l1 + l2)
    direction = rng.normal(size=3)
    return points[0] + direction / np.linalg.norm(direction) * rng.uniform(lo, hi)


def random_skeleton(rng, n, scale=False):
    """A chain of ``n`` joints with random offsets (lengths 0.3-2), rest rotations and, with
    ``scale``, uniform scales (0.5-2) per joint."""
    offsets = rng.normal(size=(n, 3))
    offsets *= rng.uniform(0.3, 2.0, size=(n, 1)) / np.linalg.norm(offsets, axis=1, keepdims=True)
    offsets[0] = rng.normal(size=3)
    rot = Rotation.random(n, random_state=rng.integers(1 << 31)).as_quat()
    scales = np.repeat(rng.uniform(0.5, 2.0, size=(n, 1)), 3, axis=1) if scale else None
    return Skeleton([f"j{i}" for i in range(n)], np.arange(n) - 1, offsets, rest_rotation=rot,
                    rest_scale=scales)


# ---------------------------------------------------------------------- position solvers
def test_two_bone_agrees_with_converged_fabrik_on_random_chains():
    rng = np.random.default_rng(12)
    worst = 0.0
    for _ in range(300):
        points = rng.normal(size=(3, 3)) * rng.uniform(0.1, 10.0)
        target = _reachable_target(rng, points)
        ref = reference_fabrik(points, target, tolerance=1e-13, max_iterations=200000)
        assert np.linalg.norm(ref[-1] - target) < 1e-10   # the reference did converge
        out = two_bone(points, target)
        worst = max(worst, np.abs(out - ref).max() / np.abs(points).max())
        np.testing.assert_allclose(_lengths(out), _lengths(points), rtol=1e-12)
        np.testing.assert_array_equal(out[0], points[0])
    assert worst < 1e-6, worst


def test_two_bone_out_of_reach_is_the_straight_chain():
    rng = np.random.default_rng(3)
    for _ in range(50):
        points = rng.normal(size=(3, 3))
        d = rng.normal(size=3)
        target = points[0] + d / np.linalg.norm(d) * _lengths(points).sum() * rng.uniform(1, 3)
        np.testing.assert_allclose(two_bone(points, target), reference_fabrik(points, target),
                                   atol=1e-12)


def test_fabrik_float_version_matches_numpy_version():
    rng = np.random.default_rng(5)
    for n in (2, 4, 6):
        for _ in range(20):
            chain = np.cumsum(rng.normal(size=(n, 3)), axis=0)
            target = chain[0] + rng.normal(size=3) * 0.5 * _lengths(chain).sum()
            np.testing.assert_allclose(fabrik(chain, target), reference_fabrik(chain, target),
                                       atol=1e-9)


# ---------------------------------------------------------------------- whole drags
@pytest.mark.parametrize("chain_length, scale", [(1, False), (2, False), (2, True), (3, False),
                                                 (3, True)])
def test_drag_matches_the_old_solver_on_random_skeletons(chain_length, scale):
    rng = np.random.default_rng(100 + 10 * chain_length + scale)
    n = 5
    for _ in range(40):
        sk = random_skeleton(rng, n, scale)
        pose = Pose(sk)
        pose.rotation[:] = Rotation.random(n, random_state=rng.integers(1 << 31)).as_quat()
        model = local_to_model(sk, pose)
        end = n - 1
        chain = list(range(end - chain_length, end))
        points = model[chain + [end], :3, 3]
        if chain_length == 2:
            target = _reachable_target(rng, points)
        else:   # inside the reach (FABRIK converges), or any direction for one bone
            d = rng.normal(size=3)
            target = points[0] + d / np.linalg.norm(d) * 0.6 * _lengths(points).sum()
        ref = pose.copy()
        if chain_length == 2:   # the closed form against FABRIK converged
            reference_solve_chain(sk, ref, chain, end, target)
        else:   # the same FABRIK as before, to the editor's tolerance
            reference_solve_chain(sk, ref, chain, end, target, 1e-6, 30)
        drag_joint(sk, pose, end, target, chain_length)
        new, old = local_to_model(sk, pose), local_to_model(sk, ref)
        np.testing.assert_allclose(new[:, :3, 3], old[:, :3, 3], atol=1e-6)
        np.testing.assert_allclose(new[:, :3, :3], old[:, :3, :3], atol=1e-6)
        if chain_length > 1:
            np.testing.assert_allclose(new[end, :3, 3], target, atol=1e-6)
        # Bone lengths of the chain are those of the pose before the drag.
        np.testing.assert_allclose(_lengths(new[chain + [end], :3, 3]), _lengths(points),
                                   rtol=1e-9)


def test_solve_chain_across_a_joint_outside_the_chain():
    """Chain joints need not be parent and child: a joint between them is carried along."""
    rng = np.random.default_rng(8)
    for _ in range(20):
        sk = random_skeleton(rng, 6)
        pose = Pose(sk)
        chain, end = [1, 3], 5   # joints 2 and 4 turn with their parents
        points = local_to_model(sk, pose)[chain + [end], :3, 3]
        target = _reachable_target(rng, points)
        ref = pose.copy()
        reference_solve_chain(sk, ref, chain, end, target)
        solve_chain(sk, pose, chain, end, target, lambda p: local_to_model(sk, p))
        new, old = local_to_model(sk, pose), local_to_model(sk, ref)
        np.testing.assert_allclose(new[:, :3, 3], old[:, :3, 3], atol=1e-6)
        np.testing.assert_allclose(new[end, :3, 3], target, atol=1e-6)


def test_drag_keeps_twist():
    """Each chain joint turns by the smallest rotation taking its bone (in its parent's frame)
    to the new direction: no part of the change is a turn about the bone."""
    rng = np.random.default_rng(21)
    for _ in range(40):
        sk = random_skeleton(rng, 4)
        pose = Pose(sk)
        before = pose.copy()
        end = 3
        target = _reachable_target(rng, local_to_model(sk, pose)[1:, :3, 3])
        drag_joint(sk, pose, end, target, 2)
        for j in (1, 2):
            r_old = Rotation.from_quat(before.rotation[j])
            r_new = Rotation.from_quat(pose.rotation[j])
            bone_old = r_old.apply(sk.rest_translation[j + 1])   # parent space
            bone_new = r_new.apply(sk.rest_translation[j + 1])
            rotvec = (r_new * r_old.inv()).as_rotvec()
            assert abs(np.dot(rotvec, bone_old)) < 1e-9 * np.linalg.norm(bone_old)
            swing = _reference_rotation_between(bone_old, bone_new)
            assert (swing.inv() * r_new * r_old.inv()).magnitude() < 1e-9


# ---------------------------------------------------------------------- degenerate cases
def _bent_leg():
    """Three joints: base at the origin, middle at (0, -1, 0), end at (0.5, -1.5, 0)."""
    return np.array([[0.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.5, -1.5, 0.0]])


def test_two_bone_target_at_the_base_folds_along_the_first_bone():
    points = _bent_leg()
    out = two_bone(points, points[0])
    np.testing.assert_allclose(out[1], points[1], atol=1e-12)   # the first bone stays
    np.testing.assert_allclose(_lengths(out), _lengths(points), rtol=1e-12)
    # As close to the base as the two lengths allow.
    l1, l2 = _lengths(points)
    np.testing.assert_allclose(np.linalg.norm(out[2] - out[0]), abs(l1 - l2), atol=1e-12)


def test_two_bone_too_close_folds_on_the_target_line():
    points = _bent_leg()   # lengths 1 and 0.707: nothing reaches nearer than 0.293
    target = np.array([0.0, 0.0, 0.1])
    out = two_bone(points, target)
    np.testing.assert_allclose(out[1], [0, 0, 1.0], atol=1e-12)
    np.testing.assert_allclose(out[2], [0, 0, 1 - np.sqrt(0.5)], atol=1e-12)


def test_two_bone_collinear_target_keeps_the_chain_bend_plane():
    points = _bent_leg()   # bends in the XY plane, the end to +x of the middle
    target = np.array([0.0, -1.2, 0.0])   # on the base-middle line
    out = two_bone(points, target)
    np.testing.assert_allclose(out[2], target, atol=1e-12)
    np.testing.assert_allclose(_lengths(out), _lengths(points), rtol=1e-12)
    assert abs(out[1, 2]) < 1e-12   # still in the XY plane
    # The elbow keeps its side: opposite the end's side of the base-end line, as before.
    assert out[1, 0] < 0


def test_two_bone_straight_chain_bends_about_the_frame_axis():
    points = np.array([[0.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, -2.0, 0.0]])
    target = np.array([0.0, -1.5, 0.0])   # straight up along the leg
    out = two_bone(points, target, frame=np.eye(3))
    np.testing.assert_allclose(out[2], target, atol=1e-12)
    np.testing.assert_allclose(_lengths(out), 1.0, rtol=1e-12)
    assert abs(out[1, 0]) < 1e-12 and out[1, 2] > 0.5   # bent about X, the knee to +Z
    # A frame turned about the leg turns the hinge with it: X is now -Z, the knee goes to +X.
    frame = Rotation.from_euler("y", 90, degrees=True).as_matrix()
    out = two_bone(points, target, frame=frame)
    np.testing.assert_allclose(out[2], target, atol=1e-12)
    assert abs(out[1, 2]) < 1e-12 and out[1, 0] > 0.5


def test_two_bone_zero_length_bones_stay_finite():
    target = np.array([0.3, 0.4, 2.0])
    first = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    out = two_bone(first, target)
    np.testing.assert_allclose(out[:2], first[:2])
    np.testing.assert_allclose(out[2], target / np.linalg.norm(target), atol=1e-12)
    second = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    out = two_bone(second, target)
    np.testing.assert_allclose(out[1], target / np.linalg.norm(target), atol=1e-12)
    np.testing.assert_allclose(out[2], out[1])
    assert np.isfinite(two_bone(np.zeros((3, 3)), target)).all()


@pytest.mark.parametrize("target", [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 2.5, 0.0],
                                    [0.0, 50.0, 0.0], [0.0, -3.0, 0.0], [1e-13, 1.0, 0.0]])
def test_drag_of_a_straight_chain_gives_finite_poses_keeping_lengths(target):
    sk = chain_skeleton(4)   # joints along +Y, one apart
    for chain_length in (1, 2, 3):
        pose = Pose(sk)
        drag_joint(sk, pose, 3, target, chain_length)
        assert np.isfinite(pose.rotation).all()
        np.testing.assert_allclose(np.linalg.norm(pose.rotation, axis=1), 1.0)
        np.testing.assert_allclose(_lengths(local_to_model(sk, pose)[:, :3, 3]), 1.0, rtol=1e-9)


def test_drag_with_a_zero_length_bone_gives_finite_poses():
    sk = Skeleton(["a", "b", "c", "d"], [-1, 0, 1, 2],
                  np.array([[0, 0, 0], [0, 1, 0], [0, 0, 0], [0, 1, 0]], dtype=float))
    for target in ([0.5, 1.2, 0.3], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0], [5.0, 5.0, 5.0]):
        for chain_length in (1, 2):
            pose = Pose(sk)
            drag_joint(sk, pose, 3, target, chain_length)
            new = local_to_model(sk, pose)[:, :3, 3]
            assert np.isfinite(new).all()
            np.testing.assert_allclose(_lengths(new), [1.0, 0.0, 1.0], atol=1e-12)
