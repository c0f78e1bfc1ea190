"""Key reduction compiled (numba): the same insertion as :func:`rigedit.compression.reduce.
reduce_keys` (a key at the worst frame of every span over the tolerance, until none is), run
span by span on a stack, so each frame is measured once per level of splitting instead of
once per pass over the whole track; and :func:`reduce_many_cubic`, the same for Catmull-Rom
keys (:func:`rigedit.compression.reduce_cubic.reduce_cubic`). Imported through
:func:`rigedit.compression.kernels.load`; the numpy versions are the reference the tests
compare them with."""
from __future__ import annotations

import numba
import numpy as np

__all__ = ["reduce_many", "reduce_many_cubic"]


@numba.njit(cache=True, inline="always")
def _line_error(vals, ref_row, a, b, u, flip, rotation, q):
    """Distance of the LERP / NLERP of keys a, b at fraction u from ``ref_row``."""
    c = q.shape[0]
    n = 0.0
    for m in range(c):
        q[m] = vals[a, m] + (flip * vals[b, m] - vals[a, m]) * u
        n += q[m] * q[m]
    scale = 1.0 / np.sqrt(n) if rotation and n > 0 else 1.0
    e1 = 0.0
    e2 = 0.0
    for m in range(c):
        v = q[m] * scale
        e1 += (v - ref_row[m]) ** 2
        e2 += (v + ref_row[m]) ** 2
    return np.sqrt(min(e1, e2)) if rotation else np.sqrt(e1)


@numba.njit(cache=True)
def _span_worst(times, ref, vals, a, b, rotation, mids, mid_ref, mid_arc3):
    """The frame to key in span (a, b), interpolating keys a and b, and its error: the worst
    of the frames strictly inside and, where the span turns far enough (its quaternion arc
    cubed over ``mid_arc3``), of the half-frames (``mids``, may be empty) a key can mend (not
    the one between two neighbouring keys; :mod:`rigedit.compression.reduce`)."""
    c = ref.shape[1]
    worst, at = -1.0, -1
    flip = 1.0
    d = 0.0
    if rotation:
        for m in range(c):
            d += vals[a, m] * vals[b, m]
        flip = -1.0 if d < 0 else 1.0
    span = times[b] - times[a]
    q = np.empty(c)
    for f in range(a + 1, b):
        u = (times[f] - times[a]) / span if span > 0 else 0.0
        e = _line_error(vals, ref[f], a, b, u, flip, rotation, q)
        if e > worst:
            worst, at = e, f
    if mids.shape[0] and b - a > 1 and np.arccos(min(abs(d), 1.0)) ** 3 > mid_arc3:
        for g in range(a, b):
            u = (mids[g] - times[a]) / span if span > 0 else 0.0
            e = _line_error(vals, mid_ref[g], a, b, u, flip, rotation, q)
            if e > worst:
                worst, at = e, (g if g > a else g + 1)
    return at, worst


@numba.njit(cache=True)
def reduce_many(times, ref, vals, tol, rotation, mids, mid_ref, keep, mid_check):
    """``keep`` (T, F) bool filled for tracks ref, vals (T, F, C) at tolerances tol (T,);
    ``mids`` (F - 1,) half-frame times and ``mid_ref`` (T, F - 1, C) the source there (both
    empty: frames only), measured in spans whose quaternion arc cubed exceeds ``mid_check``
    tolerances."""
    t, f = keep.shape
    stack = np.empty((2 * f + 2, 2), dtype=np.int64)
    for k in range(t):
        keep[k, :] = False
        keep[k, 0] = True
        keep[k, f - 1] = True
        top = 0
        stack[0, 0], stack[0, 1] = 0, f - 1
        top = 1
        while top:
            top -= 1
            a, b = stack[top, 0], stack[top, 1]
            if b - a < 2:
                continue
            at, worst = _span_worst(times, ref[k], vals[k], a, b, rotation, mids, mid_ref[k],
                                    mid_check * tol[k])
            if worst > tol[k]:
                keep[k, at] = True
                stack[top, 0], stack[top, 1] = a, at
                stack[top + 1, 0], stack[top + 1, 1] = at, b
                top += 2


@numba.njit(cache=True, inline="always")
def bessel(p0, p1, p2, p3, h0, h, h2):
    """The velocities at the span's two keys (one component; :mod:`rigedit.compression.
    cubic`): of the parabola through each key and its neighbours, the secant at an end."""
    s12 = (p2 - p1) / h if h > 0 else 0.0
    m1 = (h * ((p1 - p0) / h0) + h0 * s12) / (h0 + h) if h0 > 0 else s12
    m2 = (h2 * s12 + h * ((p3 - p2) / h2)) / (h + h2) if h2 > 0 else s12
    return m1, m2


@numba.njit(cache=True, inline="always")
def cubic_component(p0, p1, p2, p3, h0, h, h2, u):
    """One component of the Catmull-Rom cubic of the span (p1, p2) at fraction ``u``: the
    Hermite basis with :func:`bessel`'s velocities (the arithmetic of
    :func:`rigedit.compression.cubic.hermite_cr`, in its order)."""
    m1, m2 = bessel(p0, p1, p2, p3, h0, h, h2)
    u2 = u * u
    u3 = u2 * u
    return ((2 * u3 - 3 * u2 + 1) * p1 + (-2 * u3 + 3 * u2) * p2 + ((u3 - 2 * u2 + u) * h) * m1
            + ((u3 - u2) * h) * m2)


@numba.njit(cache=True)
def _aligned(vals, i, ref_row, out):
    """vals[i] into out, on the hemisphere of ref_row."""
    c = vals.shape[1]
    d = 0.0
    for m in range(c):
        d += vals[i, m] * ref_row[m]
    s = -1.0 if d < 0 else 1.0
    for m in range(c):
        out[m] = s * vals[i, m]


@numba.njit(cache=True)
def _cubic_at(times, p, h0, h, h2, a, t, rotation, q):
    """The cubic of the span starting at key ``a`` (keys ``p`` (4, C)) at time ``t``, into q."""
    c = q.shape[0]
    u = (t - times[a]) / h if h > 0 else 0.0
    n = 0.0
    for m in range(c):
        q[m] = cubic_component(p[0, m], p[1, m], p[2, m], p[3, m], h0, h, h2, u)
        n += q[m] * q[m]
    if rotation and n > 0:
        n = np.sqrt(n)
        for m in range(c):
            q[m] = q[m] / n


@numba.njit(cache=True)
def _off(q, ref, rotation):
    """Distance of q from ref (quaternions: from the nearer of ref and -ref)."""
    e1 = 0.0
    e2 = 0.0
    for m in range(q.shape[0]):
        e1 += (q[m] - ref[m]) ** 2
        e2 += (q[m] + ref[m]) ** 2
    return np.sqrt(min(e1, e2)) if rotation else np.sqrt(e1)


@numba.njit(cache=True)
def _cubic_span_worst(times, ref, vals, i0, a, b, i3, rotation, p, mids, mid_ref):
    """The frame to key in span (a, b) under the Catmull-Rom cubic of keys i0, a, b, i3
    (:mod:`rigedit.compression.reduce_cubic`): ``(frame, worst error)`` over its inner frames
    and its half-frames; frame -1 when the worst is a half-frame between a and b = a + 1
    (no key mends it). ``p`` (4, C) scratch."""
    c = ref.shape[1]
    for m in range(c):
        p[1, m] = vals[a, m]
    if rotation:
        _aligned(vals, i0, p[1], p[0])
        _aligned(vals, b, p[1], p[2])
        _aligned(vals, i3, p[2], p[3])
    else:
        for m in range(c):
            p[0, m] = vals[i0, m]
            p[2, m] = vals[b, m]
            p[3, m] = vals[i3, m]
    h0, h, h2 = times[a] - times[i0], times[b] - times[a], times[i3] - times[b]
    worst, at = -1.0, -1
    q = np.empty(c)
    for f in range(a + 1, b):
        _cubic_at(times, p, h0, h, h2, a, times[f], rotation, q)
        e = _off(q, ref[f], rotation)
        if e > worst:
            worst, at = e, f
    for g in range(a, b):
        _cubic_at(times, p, h0, h, h2, a, mids[g], rotation, q)
        e = _off(q, mid_ref[g], rotation)
        if e > worst:
            worst = e
            at = g if g > a else (g + 1 if g + 1 < b else -1)
    return at, worst


@numba.njit(cache=True)
def reduce_many_cubic(times, ref, vals, tol, rotation, mids, mid_ref, keep, ok):
    """:func:`rigedit.compression.reduce_cubic.reduce_cubic` compiled: ``keep`` (T, F) and
    ``ok`` (T,) filled for tracks ref, vals (T, F, C), half-frames ``mids`` (F - 1,) and the
    source there ``mid_ref`` (T, F - 1, C). In passes; a pass measures only the spans one of
    whose four keys is new (the others are as they were)."""
    t, f = keep.shape
    c = ref.shape[2]
    kk = np.empty(f, dtype=np.int64)
    add = np.empty(f, dtype=np.int64)
    fresh = np.zeros(f, dtype=np.bool_)
    p = np.empty((4, c))
    for k in range(t):
        keep[k, :] = False
        keep[k, 0] = True
        keep[k, f - 1] = True
        ok[k] = True
        fresh[:] = False
        fresh[0] = True
        fresh[f - 1] = True
        while ok[k]:
            n = 0
            for i in range(f):
                if keep[k, i]:
                    kk[n] = i
                    n += 1
            added = 0
            for s in range(n - 1):
                a, b = kk[s], kk[s + 1]
                i0 = kk[s - 1] if s > 0 else a
                i3 = kk[s + 2] if s + 2 < n else b
                if not (fresh[i0] or fresh[a] or fresh[b] or fresh[i3]):
                    continue
                at, worst = _cubic_span_worst(times, ref[k], vals[k], i0, a, b, i3, rotation,
                                              p, mids, mid_ref[k])
                if worst > tol[k]:
                    if at < 0:
                        ok[k] = False
                    add[added] = at
                    added += 1
            for i in range(n):
                fresh[kk[i]] = False
            if added == 0 or not ok[k]:
                break
            for i in range(added):
                keep[k, add[i]] = True
                fresh[add[i]] = True
