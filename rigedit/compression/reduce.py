"""Key reduction with non-uniform key times: the lecture's insertion.

A track starts with its first and last frame as keys; at every pass, each span between two
keys whose interpolation strays more than the tolerance from the reference at some frame gets
a key at its worst frame, until every frame is within the bound. The keys are the quantised
values (what the decoder reads), so the error measured here is the decoded one. All tracks
of one width run together: one pass is a handful of numpy operations over (T, F) arrays.

Given the source halfway between frames, the half-frames of a rotation count too: NLERP over a
span turns unevenly where the source turns evenly frame to frame (by up to about a 60th of
the span's arc cubed, quaternion arc ``a = acos |q_a . q_b|``; none at the span's middle),
and strays most between frames (7 cm halfway between frames of RobotExpressive's Jump, with
every frame within 0.05 cm). A span is measured there when ``a^3`` exceeds
:data:`MID_CHECK_ARC3` tolerances (a tenth of the tolerance, after the 60th); otherwise NLERP
is a line to well within the tolerance, and a line between keys against the source's frames
joined by lines errs most at a frame. For the same reason vectors are not measured there:
LERP against a source's frames joined by LERP differ by a line between two frames. A bad half-frame asks for a key at the frame on its side inside the
span; one between two neighbouring keys is the source's own bend between its frames (or the
quantisation), which no key mends, and is not counted here. (The pipeline measures every
half-frame in model space after, :class:`~rigedit.compression.pipeline.HalfFrames`.)
"""
from __future__ import annotations

import numpy as np

from .cubic import neighbour_keys
from .kernels import load

__all__ = ["MID_CHECK_ARC3", "interpolate_kept", "reduce_keys", "track_error"]

#: A rotation span's half-frames are measured when its quaternion arc cubed exceeds this many
#: of its track's tolerance (module notes).
MID_CHECK_ARC3 = 6.0


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


def track_error(interp, reference, rotation):
    """Distance (...) of values (..., C) from the reference (quaternions: from the nearer of
    it and its negative, the same rotation)."""
    d = np.linalg.norm(interp - reference, axis=-1)
    if rotation:
        d = np.minimum(d, np.linalg.norm(interp + reference, axis=-1))
    return d


def _interpolate_at(times, values, keep, rotation, at):
    """Each track's LERP / NLERP of its kept keys at times ``at`` (H,), ``at[g]`` inside frame
    interval ``[g, g + 1]``: (T, H, C), and the key frames of each one's span (T, H) x 2."""
    prev, nxt = (i[:, :-1] for i in neighbour_keys(keep)[1:3])
    t0, t1 = times[prev], times[nxt]
    u = (at[None] - t0) / np.where(t1 > t0, t1 - t0, 1.0)
    a = np.take_along_axis(values, prev[..., None], axis=1)
    b = np.take_along_axis(values, nxt[..., None], axis=1)
    if rotation:
        b = np.where(np.sum(a * b, axis=-1, keepdims=True) < 0, -b, b)
        q = a + (b - a) * u[..., None]
        return q / np.linalg.norm(q, axis=-1, keepdims=True), prev, nxt
    return a + (b - a) * u[..., None], prev, nxt


def reduce_keys(times, reference, values, tol, rotation, compiled=True, mid_reference=None):
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
    mid_reference : (T, F - 1, C) float64, optional
        Rotations: the source halfway between frames (:func:`~rigedit.compression.
        reduce_cubic.half_frames`), held too in spans that turn far enough for it to matter
        (module notes).

    Returns
    -------
    keep : (T, F) bool
        Always the first and the last frame; a track whose quantised values already miss the
        tolerance at a frame keeps every frame (the caller sees it in :func:`track_error`).
    """
    t, f = reference.shape[:2]
    keep = np.zeros((t, f), dtype=bool)
    keep[:, 0] = keep[:, -1] = True
    if f <= 2:
        keep[:] = True
        return keep
    mids = 0.5 * (times[:-1] + times[1:])
    if mid_reference is None or not rotation:     # no half-frames measured
        mid_reference = np.zeros((t, 0, reference.shape[2]))
        mids = mids[:0]
    kernels = load("reduce_kernels") if compiled else None
    if kernels is not None:
        kernels.reduce_many(np.ascontiguousarray(times, dtype=np.float64),
                            np.ascontiguousarray(reference, dtype=np.float64),
                            np.ascontiguousarray(values, dtype=np.float64),
                            np.asarray(tol, dtype=np.float64).reshape(-1), bool(rotation),
                            np.ascontiguousarray(mids),
                            np.ascontiguousarray(mid_reference, dtype=np.float64), keep,
                            MID_CHECK_ARC3)
        return keep
    tol = np.asarray(tol, dtype=np.float64)[:, None]
    index = np.arange(f)
    for _ in range(f):
        err = track_error(interpolate_kept(times, values, keep, rotation), reference, rotation)
        err[keep] = 0.0
        frame = np.broadcast_to(index, keep.shape)
        span = np.maximum.accumulate(np.where(keep, index, 0), axis=1)
        if len(mids):
            mid, a, b = _interpolate_at(times, values, keep, rotation, mids)
            mid_err = track_error(mid, mid_reference, rotation)
            at = np.where(index[None, :-1] > a, index[None, :-1], index[None, 1:])
            dot = np.abs(np.sum(np.take_along_axis(values, a[..., None], axis=1)
                                * np.take_along_axis(values, b[..., None], axis=1), axis=-1))
            turns = np.arccos(np.minimum(dot, 1.0)) ** 3 > MID_CHECK_ARC3 * tol
            err = np.concatenate([err, np.where((at < b) & turns, mid_err, 0.0)], axis=1)
            frame = np.concatenate([frame, at], axis=1)
            span = np.concatenate([span, a], axis=1)
        bad = err > tol
        if not bad.any():
            break
        rows, cols = np.nonzero(bad)
        worst = err[rows, cols]
        key = rows * f + span[rows, cols]
        order = np.lexsort((-worst, key))
        pick = order[np.r_[True, key[order][1:] != key[order][:-1]]]
        keep[rows[pick], frame[rows[pick], cols[pick]]] = True
    return keep
