"""Inverse kinematics for dragging joints: two-bone closed form, FABRIK chains, aiming.

The editor calls :func:`drag_joint` once per mouse move, which picks what to move for a dragged
joint (a root translates, a joint with a parent rotates its chain) and writes the result into a
:class:`Pose`. Where the chain's points go comes from :mod:`.ik_points`: a chain of two rotated
joints (three points: thigh, shin, foot) in closed form (:func:`two_bone`), longer chains with
FABRIK (:func:`fabrik`). The solved positions are then turned back into local rotations one
joint at a time from the top of the chain, each the smallest rotation that points the bone at
its solved child position, so twist is kept.

Why plain floats: a drag step rotates two to four joints. At that size SciPy's per-call overhead
(a few microseconds for each ``Rotation`` object) is most of the cost, so the per-step
quaternion arithmetic here is written on Python floats, and the chain's model matrices are
carried down the chain from the parent's matrix and the new local rotation instead of
recomputing the whole skeleton's forward kinematics after each joint. SciPy's ``Rotation``
stays the public type of :func:`rotation_between`. No kept library solves IK on our pose
representation, hence this module.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from .ik_points import _TINY, _cross, _dot, _norm, _sub, _unit_or, fabrik, two_bone
from .kinematics import local_to_model

__all__ = ["fabrik", "two_bone", "aim_joint", "ik_chain", "solve_chain", "drag_joint",
           "rotation_between"]


# ---------------------------------------------------------------------- rotations
def _arc(a, b):
    """Quaternion (x, y, z, w) of the smallest rotation taking direction ``a`` to ``b``;
    None when either has no length."""
    na, nb = _norm(a), _norm(b)
    if na <= _TINY or nb <= _TINY:
        return None
    a = [c / na for c in a]
    b = [c / nb for c in b]
    axis = _cross(a, b)
    s, c = _norm(axis), _dot(a, b)
    if s < _TINY:
        if c > 0:
            return [0.0, 0.0, 0.0, 1.0]
        # Opposite: half a turn about an axis perpendicular to a.
        perp = _cross(a, [1.0, 0.0, 0.0])
        if _norm(perp) < 1e-6:
            perp = _cross(a, [0.0, 1.0, 0.0])
        return _unit_or(perp) + [0.0]
    half = 0.5 * math.atan2(s, c)
    k = math.sin(half) / s
    return [axis[0] * k, axis[1] * k, axis[2] * k, math.cos(half)]


def _qmul(p, q):
    """Hamilton product ``p * q`` of (x, y, z, w) quaternions (rotate by q, then by p)."""
    px, py, pz, pw = p
    qx, qy, qz, qw = q
    return [pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
            pw * qw - px * qx - py * qy - pz * qz]


def rotation_between(a, b):
    """Smallest rotation taking direction ``a`` to direction ``b``, as a :class:`Rotation`.

    A direction of zero length stands for +Y."""
    a, b = np.asarray(a, dtype=np.float64).tolist(), np.asarray(b, dtype=np.float64).tolist()
    return Rotation.from_quat(_arc(_unit_or(a), _unit_or(b)))


def _local_matrix(pose, j):
    """(4, 4) local matrix ``T · R · S`` of joint ``j`` of ``pose`` (as
    :func:`~rigedit.model.transforms.compose_trs` builds it, for one joint without SciPy's
    per-call overhead)."""
    x, y, z, w = pose.rotation[j].tolist()
    n = x * x + y * y + z * z + w * w
    s = 2.0 / n if n > 0 else 0.0
    sx, sy, sz = pose.scale[j].tolist()
    m = np.empty((4, 4))
    m[0, 0], m[0, 1], m[0, 2] = (1 - s * (y * y + z * z)) * sx, s * (x * y - z * w) * sy, \
        s * (x * z + y * w) * sz
    m[1, 0], m[1, 1], m[1, 2] = s * (x * y + z * w) * sx, (1 - s * (x * x + z * z)) * sy, \
        s * (y * z - x * w) * sz
    m[2, 0], m[2, 1], m[2, 2] = s * (x * z - y * w) * sx, s * (y * z + x * w) * sy, \
        (1 - s * (x * x + y * y)) * sz
    m[:3, 3] = pose.translation[j]
    m[3] = (0.0, 0.0, 0.0, 1.0)
    return m


def _aim(pose, parent_mat, joint, head, child_pos, target):
    """Turn ``joint``'s local rotation so ``child_pos`` swings about ``head`` towards
    ``target`` (model space) by the smallest rotation; ``parent_mat`` (4, 4) is the parent's
    model matrix, None for a root. No change when either direction has no length."""
    a, b = _sub(child_pos, head), _sub(target, head)
    if parent_mat is not None:
        # The parent's model rotation (scale divided out) turns the model-space swing into a
        # parent-space one: R_local' = Rp^-1 · delta · Rp · R_local, and Rp^-1 · delta · Rp is
        # the smallest rotation between the two directions taken into parent space.
        lin = parent_mat[:3, :3]
        rp = (lin / np.maximum(np.sqrt((lin * lin).sum(axis=0)), _TINY)).T.tolist()
        a = [_dot(rp[0], a), _dot(rp[1], a), _dot(rp[2], a)]
        b = [_dot(rp[0], b), _dot(rp[1], b), _dot(rp[2], b)]
    q = _arc(a, b)
    if q is None:
        return
    q = _qmul(q, pose.rotation[joint].tolist())
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    pose.rotation[joint] = (q[0] / n, q[1] / n, q[2] / n, q[3] / n)


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
        Model-space points. Nothing turns when either lies on the joint's head.
    """
    parent = skeleton.parents[joint]
    _aim(pose, model_mats[parent] if parent >= 0 else None, joint,
         model_mats[joint, :3, 3].tolist(), np.asarray(child_pos, dtype=np.float64).tolist(),
         np.asarray(target, dtype=np.float64).tolist())


# ---------------------------------------------------------------------- chains
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


def _path_below(parents, top, joint):
    """Joints from just below ``top`` down to ``joint`` (its descendant), top first."""
    path = []
    while joint != top:
        if joint < 0:
            raise ValueError(f"expected joint {path[0] if path else joint} to be a descendant "
                             f"of joint {top}, got none")
        path.append(int(joint))
        joint = parents[joint]
    return path[::-1]


def solve_chain(skeleton, pose, chain, end, target, fk):
    """Rotate the joints of ``chain`` (top first) so joint ``end`` reaches ``target``.

    Parameters
    ----------
    skeleton : Skeleton
    pose : Pose
        Modified in place.
    chain : list[int]
        Rotated joints, top first; each a descendant of the one before, ``end`` a descendant
        of the last one.
    end : int
    target : (3,) float
    fk : callable
        ``fk(pose) -> (J, 4, 4)`` model matrices (forward kinematics of the pose's local
        matrices). Called once: below the top of the chain each joint's model matrix is its
        parent's times its local matrix.
    """
    model = fk(pose)
    path = list(chain) + [end]
    points = model[path, :3, 3]
    target = np.asarray(target, dtype=np.float64).reshape(3)
    if len(chain) == 1:
        solved = [points[0], target]
    elif len(chain) == 2:
        solved = two_bone(points, target, frame=model[chain[1], :3, :3])
    else:
        solved = fabrik(points, target)
    parents = skeleton.parents
    top_parent = parents[chain[0]]
    parent_mat = model[top_parent] if top_parent >= 0 else None
    mat = model[chain[0]]
    for k, j in enumerate(chain):
        below = _path_below(parents, j, path[k + 1])
        between = [_local_matrix(pose, x) for x in below[:-1]]   # usually none
        offset = pose.translation[below[-1]]   # the next joint in its parent's frame
        for m in reversed(between):
            offset = m[:3, :3] @ offset + m[:3, 3]
        child = mat[:3, :3] @ offset + mat[:3, 3]
        _aim(pose, parent_mat, j, mat[:3, 3].tolist(), child.tolist(),
             np.asarray(solved[k + 1]).tolist())
        if k + 1 < len(chain):
            # Carry the new matrix down to the next chain joint and its parent.
            mat = _local_matrix(pose, j) if parent_mat is None else \
                parent_mat @ _local_matrix(pose, j)
            for m in between:
                mat = mat @ m
            parent_mat = mat
            mat = mat @ _local_matrix(pose, below[-1])


def drag_joint(skeleton, pose, joint, target, chain_length=1, fk=None):
    """Pose ``joint`` towards the model-space point ``target`` (what a gizmo drag does).

    A root (no parent) is translated there, so the whole character moves. Any other joint
    rotates its IK chain (:func:`ik_chain`): with length 1 the parent turns so the bone points
    at the target, keeping its length; a chain of 2 is solved in closed form
    (:func:`two_bone`), longer chains with FABRIK.

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
