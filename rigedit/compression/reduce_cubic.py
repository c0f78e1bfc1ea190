"""Key reduction for Catmull-Rom keys (:mod:`.cubic`): the lecture's insertion, measured at
every frame and halfway between frames.

A line between keys, against a source played as lines between its frames, errs most at a
frame: between two frames both are straight, so holding every frame holds every time. A
cubic bends between frames where the source does not, so the reducer measures it at the
half-frames too, against the source sampled there. A key changes its neighbours' tangents,
so the insertion runs in passes over whole tracks: each pass puts a key at the worst frame of
every span over the tolerance (for a worst half-frame, the frame on its side that is inside
the span), and measures again only the spans one of whose four keys is new. A track whose
cubic misses a half-frame between two neighbouring keys cannot be mended by keys: it is
reported, and its caller keeps the linear keys (:func:`~rigedit.compression.encode.
encode_tracks`).
"""
from __future__ import annotations

import numpy as np

from .cubic import hermite_cr, interpolate_cubic, neighbour_keys
from .kernels import load
from .reduce import track_error

__all__ = ["half_frames", "reduce_cubic"]


def half_frames(times):
    """The times halfway between consecutive frames, (F - 1,)."""
    times = np.asarray(times, dtype=np.float64)
    return 0.5 * (times[:-1] + times[1:])


def reduce_cubic(times, reference, values, tol, rotation, mid_reference, compiled=True):
    """Which frames to keep as Catmull-Rom keys so every frame and half-frame is within
    ``tol``.

    Parameters
    ----------
    times : (F,) float64
    reference : (T, F, C) float64
        The source tracks at every frame.
    values : (T, F, C) float64
        The quantised values at every frame (the candidates for keys).
    tol : (T,) float64
    rotation : bool
    mid_reference : (T, F - 1, C) float64
        The source at :func:`half_frames`.
    compiled : bool
        Run :func:`~rigedit.compression.reduce_kernels.reduce_many_cubic` where numba is
        there (the same keys).

    Returns
    -------
    keep : (T, F) bool
    ok : (T,) bool
        False for a track whose cubic misses a half-frame no key can mend.
    """
    t, f = reference.shape[:2]
    keep = np.zeros((t, f), dtype=bool)
    keep[:, 0] = keep[:, -1] = True
    ok = np.ones(t, dtype=bool)
    if f <= 2:
        keep[:] = True
        return keep, ok
    mids = half_frames(times)
    kernels = load("reduce_kernels") if compiled else None
    if kernels is not None:
        kernels.reduce_many_cubic(np.ascontiguousarray(times, dtype=np.float64),
                                  np.ascontiguousarray(reference, dtype=np.float64),
                                  np.ascontiguousarray(values, dtype=np.float64),
                                  np.asarray(tol, dtype=np.float64).reshape(-1), bool(rotation),
                                  mids, np.ascontiguousarray(mid_reference, dtype=np.float64),
                                  keep, ok)
        return keep, ok
    tol = np.asarray(tol, dtype=np.float64)[:, None]
    index = np.arange(f)
    for _ in range(2 * f):
        frame_err = track_error(interpolate_cubic(times, values, keep, rotation), reference,
                              rotation)
        frame_err[keep] = 0.0
        i0, i1, i2, i3 = (i[:, :-1] for i in neighbour_keys(keep))
        take = [np.take_along_axis(values, i[..., None], axis=1) for i in (i0, i1, i2, i3)]
        mid = hermite_cr(times[i0], times[i1], times[i2], times[i3], *take,
                         np.broadcast_to(mids, i1.shape), rotation)
        mid_err = track_error(mid, mid_reference, rotation)
        # the frame a bad half-frame asks for: its left frame, or its right one when the left
        # is the span's first key; none when both are keys
        at = np.where(index[None, :-1] > i1, index[None, :-1], index[None, 1:])
        stuck = (mid_err > tol) & (at >= i2) & ok[:, None]
        ok &= ~stuck.any(axis=1)
        err = np.concatenate([frame_err, np.where(at < i2, mid_err, 0.0)], axis=1)
        frame = np.concatenate([np.broadcast_to(index, keep.shape), at], axis=1)
        span = np.concatenate([np.maximum.accumulate(np.where(keep, index, 0), axis=1), i1],
                              axis=1)
        bad = (err > tol) & ok[:, None]
        if not bad.any():
            break
        rows, cols = np.nonzero(bad)
        worst = err[rows, cols]
        key = rows * f + span[rows, cols]
        order = np.lexsort((-worst, key))
        first = np.r_[True, key[order][1:] != key[order][:-1]]
        pick = order[first]
        keep[rows[pick], frame[rows[pick], cols[pick]]] = True
    return keep, ok
