"""IK on points: where a chain's joints go, before any rotation is set (used by :mod:`.ik`).

:func:`two_bone` solves a chain of three points (thigh, shin, foot) in closed form, the law of
cosines in the plane of the base, the middle point and the target; :func:`fabrik` (Aristidou
& Lasenby 2011) solves longer chains iteratively.

Written on Python floats rather than numpy rows: a drag step moves three to six points, and at
that size numpy's per-call overhead (a few microseconds for each ``np.linalg.norm`` of a
3-vector) is most of the cost. :func:`rigedit.rigging.retarget.contacts.two_bone_ik` solves the same
two-bone problem with numpy arrays over all the frames of a clip at once (retargeting).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["fabrik", "two_bone"]

_TINY = 1e-12   # lengths below this (model units) count as zero


# ---------------------------------------------------------------------- 3-vectors as floats
def _sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _norm(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def _unit_or(v, fallback=(0.0, 1.0, 0.0)):
    """``v`` made unit length; ``fallback`` when it has none."""
    n = _norm(v)
    return [c / n for c in v] if n > _TINY else list(fallback)


def _along(origin, direction, length):
    """``origin + length * direction``."""
    return [origin[0] + length * direction[0], origin[1] + length * direction[1],
            origin[2] + length * direction[2]]


def _perp(v, u):
    """The part of ``v`` perpendicular to the unit vector ``u``."""
    return _along(v, u, -_dot(v, u))


def _toward(a, b, length, fallback=(0.0, 1.0, 0.0)):
    """The point at ``length`` from ``a`` towards ``b`` (along ``fallback`` when b == a)."""
    d = _sub(b, a)
    n = _norm(d)
    if n <= _TINY:
        return _along(a, fallback, length)
    return _along(a, d, length / n)


# ---------------------------------------------------------------------- position solvers
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
    if p.ndim != 2 or p.shape[1] != 3 or len(p) < 2:
        raise ValueError(f"expected positions of shape (N>=2, 3), got {p.shape}")
    t = np.asarray(target, dtype=np.float64).reshape(3).tolist()
    pts = p.tolist()
    n = len(pts)
    lengths = [math.dist(pts[i], pts[i + 1]) for i in range(n - 1)]
    base = pts[0]
    dist = math.dist(base, t)
    if dist >= sum(lengths):
        # Out of reach: stretch straight towards the target.
        direction = _unit_or(_sub(t, base) if dist > _TINY else _sub(pts[-1], base))
        reach = 0.0
        for i in range(1, n):
            reach += lengths[i - 1]
            pts[i] = _along(base, direction, reach)
        return np.array(pts)
    for _ in range(max_iterations):
        if math.dist(pts[-1], t) <= tolerance:
            break
        pts[-1] = t  # backward pass: from the end to the base
        for i in range(n - 2, -1, -1):
            pts[i] = _toward(pts[i + 1], pts[i], lengths[i])
        pts[0] = base  # forward pass: from the base to the end
        for i in range(1, n):
            pts[i] = _toward(pts[i - 1], pts[i], lengths[i - 1])
    return np.array(pts)


def two_bone(positions, target, frame=None):
    """Closed-form IK of two bones: where FABRIK on three points converges, in one step.

    The middle point stays in the plane of the base, the current middle point and the target,
    on the middle point's side of the base-target line (as FABRIK keeps it), at the angle the
    law of cosines gives, so the end lands on the target.

    Parameters
    ----------
    positions : (3, 3) float
        Base, middle and end points; the base stays fixed.
    target : (3,) float
    frame : (3, 3) float, optional
        The middle joint's model axes as columns. Used only when base, middle and target lie on
        one line and the chain itself is straight, so no bend plane is given by the points: the
        bend plane's normal is then the axis of ``frame`` least aligned with the chain (the
        hinge of a knee in a frame whose X is the hinge), the middle point going the way of
        ``chain direction x normal``. The world axes stand in when omitted.

    Returns
    -------
    solved : (3, 3) float64
        Base unchanged, bone lengths kept. Out of reach, the chain lies straight pointing at the
        target; closer to the base than ``|l1 - l2|``, it folds on the line through the target.
        A target at the base keeps the first bone's direction.
    """
    p = np.asarray(positions, dtype=np.float64)
    if p.shape != (3, 3):
        raise ValueError(f"expected positions of shape (3, 3), got {p.shape}")
    base, mid, end = p.tolist()
    t = np.asarray(target, dtype=np.float64).reshape(3).tolist()
    l1, l2 = math.dist(base, mid), math.dist(mid, end)
    if l1 <= _TINY:
        # The first bone has no length: only the second can turn.
        return np.array([base, mid, _toward(mid, t, l2, _unit_or(_sub(end, mid)))])
    to_target = _sub(t, base)
    d = _norm(to_target)
    bone = [c / l1 for c in _sub(mid, base)]
    if d <= _TINY:
        # Target at the base: no direction to aim; fold along the first bone as it points.
        u, cos_a = bone, 1.0
    else:
        u = [c / d for c in to_target]
        cos_a = min(1.0, max(-1.0, (l1 * l1 + d * d - l2 * l2) / (2.0 * l1 * d)))
    if cos_a >= 1.0:
        m = _along(base, u, l1)
    else:
        w = _bend_direction(base, mid, end, u, l1, frame)
        sin_a = math.sqrt(max(0.0, 1.0 - cos_a * cos_a))
        m = [base[i] + l1 * (cos_a * u[i] + sin_a * w[i]) for i in range(3)]
    return np.array([base, m, _toward(m, t, l2, u)])


def _bend_direction(base, mid, end, u, l1, frame):
    """Unit vector perpendicular to ``u`` towards which the middle joint bends."""
    # 1. The plane of base, middle and target (FABRIK's), on the middle joint's side.
    w = _perp(_sub(mid, base), u)
    n = _norm(w)
    if n > 1e-9 * l1:
        return [c / n for c in w]
    # 2. The middle point is on the base-target line: keep the chain's own bend (the elbow's
    #    offset from the base-end line), carried over to the base-target line.
    to_end = _sub(end, base)
    ne = _norm(to_end)
    if ne > _TINY:
        elbow = _perp(_sub(mid, base), [c / ne for c in to_end])
        w = _perp(elbow, u)
        n = _norm(w)
        if n > 1e-9 * l1:
            return [c / n for c in w]
    # 3. A straight chain pointing at the target: bend about the middle joint's own axis
    #    least aligned with the chain.
    axes = np.eye(3) if frame is None else np.asarray(frame, dtype=np.float64)
    best = None
    for k in range(3):
        axis = _unit_or(axes[:, k].tolist())
        w = _cross(u, axis)
        n = _norm(w)
        if best is None or n > best[0] + 1e-9:
            best = (n, w)
    return [c / best[0] for c in best[1]]
