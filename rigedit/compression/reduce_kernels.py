"""Key reduction compiled (numba): the same insertion as :func:`rigedit.compression.reduce.
reduce_keys` (a key at the worst frame of every span over the tolerance, until none is), run
span by span on a stack, so each frame is measured once per level of splitting instead of
once per pass over the whole track. Imported through :func:`rigedit.compression.kernels.
load`; the numpy version is the reference the tests compare it with."""
from __future__ import annotations

import numba
import numpy as np

__all__ = ["reduce_many"]


@numba.njit(cache=True)
def _span_worst(times, ref, vals, a, b, rotation):
    """Worst frame strictly inside (a, b) and its error, interpolating keys a and b."""
    c = ref.shape[1]
    worst, at = -1.0, -1
    flip = 1.0
    if rotation:
        d = 0.0
        for m in range(c):
            d += vals[a, m] * vals[b, m]
        flip = -1.0 if d < 0 else 1.0
    span = times[b] - times[a]
    q = np.empty(c)
    for f in range(a + 1, b):
        u = (times[f] - times[a]) / span if span > 0 else 0.0
        n = 0.0
        for m in range(c):
            q[m] = vals[a, m] + (flip * vals[b, m] - vals[a, m]) * u
            n += q[m] * q[m]
        scale = 1.0 / np.sqrt(n) if rotation and n > 0 else 1.0
        e1 = 0.0
        e2 = 0.0
        for m in range(c):
            v = q[m] * scale
            e1 += (v - ref[f, m]) ** 2
            e2 += (v + ref[f, m]) ** 2
        e = np.sqrt(min(e1, e2)) if rotation else np.sqrt(e1)
        if e > worst:
            worst, at = e, f
    return at, worst


@numba.njit(cache=True)
def reduce_many(times, ref, vals, tol, rotation, keep):
    """``keep`` (T, F) bool filled for tracks ref, vals (T, F, C) at tolerances tol (T,)."""
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
            at, worst = _span_worst(times, ref[k], vals[k], a, b, rotation)
            if worst > tol[k]:
                keep[k, at] = True
                stack[top, 0], stack[top, 1] = a, at
                stack[top + 1, 0], stack[top + 1, 1] = at, b
                top += 2
