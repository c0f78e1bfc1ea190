"""Inverse kinematics for dragging joints: aim a bone, FABRIK chains, chain selection.

Pure numpy + scipy. The editor calls :func:`drag_joint`, which picks what to move for a dragged
joint (a root translates, a joint with a parent rotates its chain) and writes the result into a
:class:`Pose`.

FABRIK (Aristidou & Lasenby 2011) solves on positions; the positions are then turned back into
local rotations one joint at a time from the top of the chain (:func:`aim_joint`), each the
smallest rotation that points the bone at its solved child position, so twist is kept. No kept
library solves IK on our pose representation, hence this module.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from .kinematics import local_to_model

__all__ = ["fabrik", "aim_joint", "ik_chain", "solve_chain", "drag_joint", "rotation_between"]


def fabrik(positions, target, tolerance=1e-6, max_iterations=30):
    """Move a chain of points so its end reaches ``target``, keeping segment lengths.

    Parameters
    ----------
    positions : (N, 3) float
        Joint positions from the fixed base (row 0) to the end effector (row N-1), N >= 2.
    target : (3,) float
    tolerance : float
        Stop when the end is this close to the target (model units).
    max_iterations : int

    Returns
    -------
    solved : (N, 3) float64
        New positions; row 0 unchanged. When the target is out of reach the chain lies
        straight, pointing at it.
    """
    p = np.array(positions, dtype=np.float64)
    target = np.asarray(target, dtype=np.float64).reshape(3)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) < 2:
        raise ValueError(f"expected positions of shape (N>=2, 3), got {p.shape}")
    lengths = np.linalg.norm(np.diff(p, axis=0), axis=1)
    base = p[0].copy()
    to_target = target - base
    dist = np.linalg.norm(to_target)
    if dist >= lengths.sum():
        # Out of reach: stretch straight towards the target.
        direction = to_target / dist if dist > 1e-12 else _unit(p[-1] - p[0])
        p[1:] = base + np.cumsum(lengths)[:, None] * direction
        return p
    for _ in range(max_iterations):
        if np.linalg.norm(p[-1] - target) <= tolerance:
            break
        p[-1] = target  # backward pass: from the end to the base
        for i in range(len(p) - 2, -1, -1):
            p[i] = p[i + 1] + _unit(p[i] - p[i + 1]) * lengths[i]
        p[0] = base  # forward pass: from the base to the end
        for i in range(1, len(p)):
            p[i] = p[i - 1] + _unit(p[i] - p[i - 1]) * lengths[i - 1]
    return p


def _unit(v):
    n = np.linalg.norm(v)
    return v / n if n > 1e-12 else np.array([0.0, 1.0, 0.0])


def rotation_between(a, b):
    """Smallest rotation taking direction ``a`` to direction ``b``, as a :class:`Rotation`."""
    a, b = _unit(a), _unit(b)
    axis = np.cross(a, b)
    s, c = np.linalg.norm(axis), float(np.dot(a, b))
    if s < 1e-12:
        if c > 0:
            return Rotation.identity()
        # Opposite: half a turn about any axis perpendicular to a.
        perp = np.cross(a, [1.0, 0.0, 0.0])
        if np.linalg.norm(perp) < 1e-6:
            perp = np.cross(a, [0.0, 1.0, 0.0])
        return Rotation.from_rotvec(_unit(perp) * np.pi)
    return Rotation.from_rotvec(axis / s * np.arctan2(s, c))


def aim_joint(skeleton, pose, model_mats, joint, child_pos, target):
    """Rotate ``joint`` (in ``pose``, in place) so the point ``child_pos`` moves towards
    ``target`` along the smallest rotation about the joint.

    Parameters
    ----------
    skeleton : Skeleton
    pose : Pose
    model_mats : (J, 4, 4) float64
        Model matrices of ``pose`` before the change.
    joint : int
    child_pos, target : (3,) float
        Model-space points.
    """
    head = model_mats[joint, :3, 3]
    delta = rotation_between(np.asarray(child_pos) - head, np.asarray(target) - head)
    parent = skeleton.parents[joint]
    if parent >= 0:
        lin = model_mats[parent, :3, :3]
        # The parent's model rotation (scale divided out) turns the model-space delta into a
        # parent-space one: R_local' = Rp^-1 · delta · Rp · R_local.
        rp = Rotation.from_matrix(lin / np.linalg.norm(lin, axis=0, keepdims=True))
        delta = rp.inv() * delta * rp
    pose.rotation[joint] = (delta * Rotation.from_quat(pose.rotation[joint])).as_quat()


def ik_chain(skeleton, joint, length):
    """Joints an IK drag of ``joint`` rotates, from the top of the chain down.

    The chain climbs ``length`` joints above ``joint`` but stops before a root (moving a root
    is a translation, not part of a limb) and before a branching joint (a pelvis or chest with
    several children), except that the direct parent always takes part.

    Returns
    -------
    chain : list[int]
        Rotated joints, top first; empty for a root.
    """
    chain = []
    j = skeleton.parents[joint]
    while j >= 0 and len(chain) < max(1, int(length)):
        if chain and (skeleton.parents[j] < 0 or len(skeleton.children(j)) > 1):
            break
        chain.append(int(j))
        j = skeleton.parents[j]
    return chain[::-1]


def solve_chain(skeleton, pose, chain, end, target, fk):
    """Rotate the joints of ``chain`` (top first) so joint ``end`` reaches ``target``.

    Parameters
    ----------
    skeleton : Skeleton
    pose : Pose
        Modified in place.
    chain : list[int]
        Rotated joints, top first; ``end`` is a descendant of the last one.
    end : int
    target : (3,) float
    fk : callable
        ``fk(pose) -> (J, 4, 4)`` model matrices.
    """
    model = fk(pose)
    points = np.vstack([model[chain, :3, 3], model[end, :3, 3]])
    solved = fabrik(points, target) if len(chain) > 1 else np.vstack([points[0], target])
    for k, j in enumerate(chain):
        if k > 0:
            model = fk(pose)
        nxt = chain[k + 1] if k + 1 < len(chain) else end
        aim_joint(skeleton, pose, model, j, model[nxt, :3, 3], solved[k + 1])


def drag_joint(skeleton, pose, joint, target, chain_length=1, fk=None):
    """Pose ``joint`` towards the model-space point ``target`` (what a gizmo drag does).

    A root (no parent) is translated there, so the whole character moves. Any other joint
    rotates its IK chain (:func:`ik_chain`): with length 1 the parent turns so the bone points
    at the target, keeping its length; longer chains are solved with FABRIK.

    Parameters
    ----------
    skeleton : Skeleton
    pose : Pose
        Modified in place.
    joint : int
    target : (3,) float
    chain_length : int
    fk : callable, optional
        ``fk(pose) -> (J, 4, 4)``; :func:`~rigedit.model.kinematics.local_to_model` by
        default.
    """
    if fk is None:
        def fk(p):
            return local_to_model(skeleton, p)
    target = np.asarray(target, dtype=np.float64).reshape(3)
    parent = skeleton.parents[joint]
    if parent < 0:
        pose.translation[joint] = target
        return
    chain = ik_chain(skeleton, joint, chain_length)
    solve_chain(skeleton, pose, chain, joint, target, fk)
