"""Catmull-Rom keys: a cubic through the kept keys instead of a straight line between them.

The lecture's curve fitting: a track whose keys are joined by a Catmull-Rom spline needs
fewer keys than LERP / NLERP where the motion is smooth (the interpolation error of a cubic
falls with the fourth power of the key spacing, a line's with the second). Key times are
non-uniform (frame indices), so the spline is the cubic Hermite through the keys with, at each
key, the velocity of the parabola through it and its two neighbours (Bessel's tangent: on
evenly spaced keys exactly Catmull-Rom's ``(p[i+1] - p[i-1]) / (t[i+1] - t[i-1])``; on uneven
ones still exact on a parabola, where Catmull-Rom's difference is off by the spacing's
imbalance times the curvature, which costs keys where the reducer puts them unevenly)::

    s_i = (p[i+1] - p[i]) / h_i,   h_i = t[i+1] - t[i]
    m_i = (h_i s_[i-1] + h_[i-1] s_i) / (h_[i-1] + h_i)    (an end key: the secant s)

and between keys ``i`` and ``i+1``, ``h = t[i+1] - t[i]``, ``u = (t - t[i]) / h``::

    p(t) = h00(u) p[i] + h10(u) h m_i + h01(u) p[i+1] + h11(u) h m_[i+1]

It reads four keys (``i-1 .. i+2``, clamped to the track: a clamped neighbour gives the
secant), so a decoder still samples any time from a handful of keys. Rotations run the same
cubic on quaternions seen as points of R^4, each neighbour first put on its predecessor's
hemisphere (``i-1`` and ``i+1`` on key ``i``'s, ``i+2`` on ``i+1``'s), then normalised: what
the decoder does (:mod:`.codec`, :mod:`.codec_kernels`) and what :func:`interpolate_cubic`
measures. These are not the centripetal tangents of the editor's
``catmull_rom`` tracks: they need no square root per key in the decoder, and the reducer
places the keys where the error asks for them.
"""
from __future__ import annotations

import numpy as np

__all__ = ["neighbour_keys", "align_to", "hermite_cr", "interpolate_cubic", "key_tangents"]


def neighbour_keys(keep):
    """For each frame of each track, the key before and after the frame's span and their outer
    neighbours: four (T, F) int arrays ``(i0, i1, i2, i3)`` of frame indices, clamped to the
    first and last key (a key frame is the start of its span, the last frame the end of the
    last span).

    Parameters
    ----------
    keep : (T, F) bool
        The first and last frame of each track are keys.
    """
    t, f = keep.shape
    index = np.arange(f)
    prev = np.maximum.accumulate(np.where(keep, index, 0), axis=1)
    nxt = np.minimum.accumulate(np.where(keep, index, f - 1)[:, ::-1], axis=1)[:, ::-1]
    # the span of a frame is [key at or before it, next key after it]; the last frame belongs
    # to the last span
    strict_next = np.empty_like(nxt)
    strict_next[:, :-1] = nxt[:, 1:]
    strict_next[:, -1] = f - 1
    i1 = np.where(index[None] == f - 1, _before(prev, f - 1), prev)
    i2 = np.where(index[None] == f - 1, f - 1, strict_next)
    i0 = _before(prev, i1)
    i3 = np.take_along_axis(strict_next, i2, axis=1)
    return i0, i1, i2, i3


def _before(prev, at):
    """The key strictly before frame ``at`` (each track's row of ``prev``), or ``at`` itself
    at the first frame."""
    at = np.broadcast_to(at, prev.shape) if np.ndim(at) else np.full(prev.shape, at)
    before = np.take_along_axis(prev, np.maximum(at - 1, 0), axis=1)
    return np.where(at > 0, before, at)


def align_to(q, ref):
    """``q`` on the hemisphere of ``ref`` (..., 4): negated where their dot product is < 0."""
    return np.where(np.sum(q * ref, axis=-1, keepdims=True) < 0, -q, q)


def hermite_cr(t0, t1, t2, t3, p0, p1, p2, p3, t, rotation):
    """The Catmull-Rom cubic of the span ``[t1, t2]`` at times ``t`` (module notes).

    Parameters
    ----------
    t0, t1, t2, t3 : (...) float64
        Key times; ``t0 == t1`` / ``t3 == t2`` where the span is the track's first / last.
    p0, p1, p2, p3 : (..., C) float64
        Key values (quaternions aligned here).
    t : (...) float64
    rotation : bool

    Returns
    -------
    (..., C) float64
    """
    if rotation:
        p0, p2 = align_to(p0, p1), align_to(p2, p1)
        p3 = align_to(p3, p2)
    h0, h, h2 = (t1 - t0)[..., None], (t2 - t1)[..., None], (t3 - t2)[..., None]
    with np.errstate(invalid="ignore", divide="ignore"):
        s01 = np.where(h0 > 0, (p1 - p0) / np.where(h0 > 0, h0, 1.0), 0.0)
        s12 = np.where(h > 0, (p2 - p1) / np.where(h > 0, h, 1.0), 0.0)
        s23 = np.where(h2 > 0, (p3 - p2) / np.where(h2 > 0, h2, 1.0), 0.0)
        m1 = np.where(h0 > 0, (h * s01 + h0 * s12) / np.where(h0 > 0, h0 + h, 1.0), s12)
        m2 = np.where(h2 > 0, (h2 * s12 + h * s23) / np.where(h2 > 0, h + h2, 1.0), s12)
        h = h[..., 0]
        u = np.where(h > 0, (t - t1) / np.where(h > 0, h, 1.0), 0.0)
    u = np.clip(u, 0.0, 1.0)[..., None]
    u2, u3 = u * u, u * u * u
    hh = h[..., None]
    q = ((2 * u3 - 3 * u2 + 1) * p1 + (-2 * u3 + 3 * u2) * p2
         + (u3 - 2 * u2 + u) * hh * m1 + (u3 - u2) * hh * m2)
    if rotation:
        q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return q


def interpolate_cubic(times, values, keep, rotation):
    """Every frame of each track from its kept keys through the Catmull-Rom cubic: (T, F, C).

    Parameters
    ----------
    times : (F,) float64
    values : (T, F, C) float64
        Key values at every frame (only the kept ones are read).
    keep : (T, F) bool
    rotation : bool
    """
    i0, i1, i2, i3 = neighbour_keys(keep)
    take = [np.take_along_axis(values, i[..., None], axis=1) for i in (i0, i1, i2, i3)]
    return hermite_cr(times[i0], times[i1], times[i2], times[i3], *take,
                      np.broadcast_to(times, keep.shape), rotation)


def key_tangents(times, values, rotation):
    """A cubic track's keys as a chain and their velocities, for a plain Hermite track.

    Parameters
    ----------
    times : (K,) float64, K >= 2
    values : (K, C) float64
    rotation : bool

    Returns
    -------
    values : (K, C) float64
        Quaternions each on its predecessor's hemisphere (vectors unchanged).
    tangents : (K, C) float64
        d value / d t at each key (per second), the finite-difference ones of the module
        notes: sampling a Hermite track with them gives what the decoder gives.
    """
    p = np.array(values, dtype=np.float64)
    if rotation:
        for k in range(1, len(p)):
            if np.dot(p[k], p[k - 1]) < 0:
                p[k] = -p[k]
    h = np.diff(times)[:, None]
    slope = np.diff(p, axis=0) / h                           # (K-1, C)
    m = np.empty_like(p)
    m[0], m[-1] = slope[0], slope[-1]
    m[1:-1] = (h[1:] * slope[:-1] + h[:-1] * slope[1:]) / (h[:-1] + h[1:])
    return p, m
