"""Key reduction with non-uniform key times: the lecture's insertion.

A track starts with its first and last frame as keys; at every pass, each span between two
keys whose interpolation strays more than the tolerance from the reference at some frame gets
a key at its worst frame, until every frame is within the bound. The keys are the quantised
values (what the decoder reads), so the error measured here is the decoded one. All tracks
of one width run together: one pass is a handful of numpy operations over (T, F) arrays.
"""
from __future__ import annotations

import numpy as np

from .kernels import load

__all__ = ["interpolate_kept", "reduce_keys"]


def interpolate_kept(times, values, keep, rotation):
    """Every frame interpolated from the kept keys: (T, F, C).

    Parameters
    ----------
    times : (F,) float64
    values : (T, F, C) float64
        Key values at every frame (only the kept ones are read).
    keep : (T, F) bool
        The first and last frame of each track must be kept.
    rotation : bool
        NLERP on the shortest path (C = 4) instead of LERP.
    """
    t, f = keep.shape
    index = np.arange(f)
    prev = np.maximum.accumulate(np.where(keep, index, 0), axis=1)
    nxt = np.minimum.accumulate(np.where(keep, index, f - 1)[:, ::-1], axis=1)[:, ::-1]
    t0, t1 = times[prev], times[nxt]
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.where(t1 > t0, (times[None] - t0) / np.where(t1 > t0, t1 - t0, 1.0), 0.0)
    a = np.take_along_axis(values, prev[..., None], axis=1)
    b = np.take_along_axis(values, nxt[..., None], axis=1)
    if rotation:
        b = np.where(np.sum(a * b, axis=-1, keepdims=True) < 0, -b, b)
        q = a + (b - a) * u[..., None]
        return q / np.linalg.norm(q, axis=-1, keepdims=True)
    return a + (b - a) * u[..., None]


def _error(interp, reference, rotation):
    d = np.linalg.norm(interp - reference, axis=-1)
    if rotation:
        d = np.minimum(d, np.linalg.norm(interp + reference, axis=-1))
    return d


def reduce_keys(times, reference, values, tol, rotation, compiled=True):
    """Which frames to keep as keys so every frame is within ``tol`` of the reference.

    Parameters
    ----------
    times : (F,) float64
    reference : (T, F, C) float64
        The source tracks at every frame.
    values : (T, F, C) float64
        The quantised values at every frame (the candidates for keys).
    tol : (T,) float64
        Per track, in the channel's units (quaternion distance for rotations).
    rotation : bool
    compiled : bool
        Run the compiled kernel (:mod:`.reduce_kernels`) where numba is there: the same keys.

    Returns
    -------
    keep : (T, F) bool
        Always the first and the last frame; a track whose quantised values already miss the
        tolerance at a frame keeps every frame (the caller sees it in :func:`_error`).
    """
    t, f = reference.shape[:2]
    keep = np.zeros((t, f), dtype=bool)
    keep[:, 0] = keep[:, -1] = True
    if f <= 2:
        keep[:] = True
        return keep
    kernels = load("reduce_kernels") if compiled else None
    if kernels is not None:
        kernels.reduce_many(np.ascontiguousarray(times, dtype=np.float64),
                            np.ascontiguousarray(reference, dtype=np.float64),
                            np.ascontiguousarray(values, dtype=np.float64),
                            np.asarray(tol, dtype=np.float64).reshape(-1), bool(rotation), keep)
        return keep
    tol = np.asarray(tol, dtype=np.float64)[:, None]
    flat = keep.reshape(-1)
    rows = (np.arange(t) * f)[:, None]
    index = np.arange(f)
    for _ in range(f):
        err = _error(interpolate_kept(times, values, keep, rotation), reference, rotation)
        bad = (err > tol) & ~keep
        if not bad.any():
            break
        prev = np.maximum.accumulate(np.where(keep, index, 0), axis=1)
        seg = (rows + prev).reshape(-1)[bad.reshape(-1)]
        where = np.flatnonzero(bad.reshape(-1))
        worst = err.reshape(-1)[where]
        order = np.lexsort((-worst, seg))
        first = np.r_[True, seg[order][1:] != seg[order][:-1]]
        flat[where[order][first]] = True
    return keep
