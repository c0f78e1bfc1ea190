"""Tracks as curves: any track's three :class:`~rigedit.animation.curve.Curve`, and the key
edits of a bezier track's curves (removing and retiming keys by time).

Conversion (:func:`curves_from_track`), per mode of the track:

=========================================  ===============================================
``step``                                   ``constant`` keys
``linear``                                 ``linear`` keys (exact)
``nlerp``, ``slerp``, ``hybrid``           ``bezier`` keys whose handles follow the
(rotations)                                track's Euler velocity on each side of the key
                                           (a finite difference), or per segment the Euler
                                           secant or a least-squares fit of its Euler
                                           angles where either is nearer the track (near
                                           gimbal lock; :func:`_best_segments`): Euler
                                           angles running linearly between keys would
                                           leave the arc slerp takes (9 degrees off
                                           mid-segment on keys 25 to 123 degrees apart;
                                           these handles: under 0.2 for slerp, under 0.5
                                           for nlerp)
``catmull_rom``, ``cubic_spline``          ``bezier`` keys with handles a third of
                                           each segment long: exact for vectors (a cubic
                                           Hermite is that Bezier); for a rotation the
                                           handles follow the Euler velocity as above (a
                                           cubic in Euler angles is not one in quaternions:
                                           up to 2.3 degrees apart mid-segment on the same
                                           keys)
=========================================  ===============================================

Converted handles are ``aligned`` where the key's velocity is the same on both sides (a
dragged handle then keeps the key smooth), ``free`` where it is not (a slerp's keys, a
cubic_spline's own in- and out-tangents). Rotations become Euler angles per key in degrees
(:func:`~.euler_curves.quat_to_euler`, unwrapped so the curves stay continuous across +-180
degrees).
"""
from __future__ import annotations

import numpy as np

from .curve import Curve
from .euler_curves import DEFAULT_ORDER, euler_to_quat, nearest, principal, quat_to_euler

__all__ = ["curves_from_track", "remove_times", "retime"]

_KIND = {"step": "constant", "linear": "linear", "nlerp": "bezier", "slerp": "bezier",
         "hybrid": "bezier", "catmull_rom": "bezier", "cubic_spline": "bezier"}


def _slopes(track, euler, euler_order):
    """(K, 2, 3) in- and out-velocities (per second) of a spline track at its keys: its
    tangents for vectors, a finite difference of its Euler angles for rotations."""
    if track.channel != "rotation":
        tan = track.tangents
        return tan if tan.ndim == 3 else np.repeat(tan[:, None], 2, axis=1)
    times = track.times
    span = np.min(np.diff(times)) if len(times) > 1 else 1.0
    eps = 1e-4 * span
    out = np.empty((len(times), 2, 3))
    for side, sign in ((0, -1.0), (1, 1.0)):
        near = track.sample_many(times + sign * eps)
        angles = nearest(principal(near, euler_order), euler_order, euler)
        out[:, side] = sign * (angles - euler) / eps
    # the end keys' outer sides are clamped (no motion beyond the keys): reuse the inner one
    out[0, 0], out[-1, 1] = out[0, 1], out[-1, 0]
    return _best_segments(track, euler, euler_order, out)


#: Inner points (fractions of a segment) where converted rotation segments are compared.
_PROBES = np.arange(1, 8) / 8.0


def _hermite_basis(s):
    """(S, 4) cubic Hermite weights of value 0, slope 0 (times the span), value 1, slope 1."""
    s2, s3 = s * s, s * s * s
    return np.stack([2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, -2 * s3 + 3 * s2, s3 - s2], axis=1)


def _best_segments(track, euler, order, slopes):
    """(K, 2, 3) ``slopes`` with each segment's pair (key k's out-, key k + 1's in-velocity)
    replaced by the best of three candidates, by the largest angle between the Euler cubic
    and the track at :data:`_PROBES`: the finite difference, the Euler secant (angles
    running linearly), and a least-squares fit of the segment's Euler angles.

    The finite difference is the track's true Euler velocity at the keys, but near gimbal
    lock (the middle angle near +-90 degrees) that velocity grows without bound (the first
    and last angles swing against each other) and a cubic through it overshoots by
    thousands of degrees: 84 degrees off the track between keys where a key is at Y = 90.
    """
    times = track.times
    dt = np.diff(times)
    probe_t = (times[:-1, None] + dt[:, None] * _PROBES[None, :]).reshape(-1)
    truth = track.sample_many(probe_t).reshape(len(dt), len(_PROBES), 4)
    basis = _hermite_basis(_PROBES)                            # (S, 4)
    v0, v1 = euler[:-1], euler[1:]                             # (K-1, 3)
    ends = basis[None, :, 0, None] * v0[:, None] + basis[None, :, 2, None] * v1[:, None]
    # the segment's Euler angles: the triple of each probe nearest the straight line
    line = v0[:, None] + (v1 - v0)[:, None] * _PROBES[None, :, None]
    target = nearest(principal(truth.reshape(-1, 4), order), order,
                     line.reshape(-1, 3)).reshape(line.shape)
    fit = np.linalg.pinv(basis[:, [1, 3]]) @ (target - ends).transpose(1, 0, 2).reshape(
        len(_PROBES), -1)                                      # (2, (K-1) * 3)
    fit = fit.reshape(2, len(dt), 3).transpose(1, 0, 2) / dt[:, None, None]
    secant = ((v1 - v0) / dt[:, None])[:, None].repeat(2, axis=1)
    finite = np.stack([slopes[:-1, 1], slopes[1:, 0]], axis=1)   # (K-1, 2, 3)
    errors, candidates = [], (finite, secant, fit)
    for m in candidates:
        angles = ends + dt[:, None, None] * (basis[None, :, 1, None] * m[:, None, 0]
                                             + basis[None, :, 3, None] * m[:, None, 1])
        q = euler_to_quat(angles.reshape(-1, 3), order).reshape(truth.shape)
        dot = np.clip(np.abs(np.sum(q * truth, axis=-1)), 0.0, 1.0)
        errors.append(np.max(2 * np.arccos(dot), axis=1))
    # ties keep the finite difference (the track's own velocity: smooth keys stay aligned)
    best = np.argmin(np.stack(errors) - np.array([1e-9, 0, 0])[:, None], axis=0)
    chosen = np.stack(candidates)[best, np.arange(len(dt))]
    out = slopes.copy()
    out[:-1, 1], out[1:, 0] = chosen[:, 0], chosen[:, 1]
    # the end keys' outer handles (unused: the curve holds beyond the keys) follow the inner
    # ones, not a finite difference that may be 80,000 degrees out (framing takes handles)
    out[0, 0], out[-1, 1] = out[0, 1], out[-1, 0]
    return out


def curves_from_track(track, euler_order=DEFAULT_ORDER):
    """The three curves (X, Y, Z) of a track; a bezier track's own.

    Parameters
    ----------
    track : Track
    euler_order : str
        For a rotation track that is not bezier yet: the order of its Euler angles.

    Returns
    -------
    curves : tuple of 3 Curve
    """
    if track.curves is not None:
        return track.curves
    times = track.times
    rotation = track.channel == "rotation"
    values = quat_to_euler(track.values, euler_order) if rotation else track.values
    kind = _KIND[track.interpolation]
    if kind != "bezier" or len(times) < 2:
        return tuple(Curve(times, values[:, a], kind) for a in range(3))
    slopes = _slopes(track, values, euler_order)
    dt = np.diff(times)
    before, after = np.r_[dt[0], dt] / 3, np.r_[dt, dt[-1]] / 3
    curves = []
    for a in range(3):
        v = values[:, a]
        left = np.stack([times - before, v - slopes[:, 0, a] * before], axis=1)
        right = np.stack([times + after, v + slopes[:, 1, a] * after], axis=1)
        # a smooth key (the same velocity on both sides) keeps its handles collinear
        smooth = np.isclose(slopes[:, 0, a], slopes[:, 1, a], rtol=1e-6, atol=1e-9)
        kind = np.where(smooth, "aligned", "free").astype(object)
        curves.append(Curve(times, v, "bezier", left, right, kind, kind))
    return tuple(curves)


def _key_mask(curve, times, tol):
    return np.any(np.abs(curve.times[:, None] - np.asarray(times)[None, :]) <= tol, axis=1)


def remove_times(curves, times, tol):
    """The curves without their keys within ``tol`` of ``times``; a curve left without keys
    holds its old value at the first remaining key time of the others. None when no curve
    keeps a key."""
    kept = [c.without_keys(np.flatnonzero(_key_mask(c, times, tol))) for c in curves]
    if all(k is None for k in kept):
        return None
    first = min(k.times[0] for k in kept if k is not None)
    return tuple(Curve([first], [c.sample(first)]) if k is None else k
                 for c, k in zip(curves, kept))


def retime(curve, mapping, tol):
    """``curve`` with keys moved in time: ``mapping`` is ``{old time: new time}``; a moved key
    keeps its handles' offsets and replaces an unmoved key at its new time. The curve itself
    when no key is at an old time."""
    src, dst = [], []
    for old, new in mapping.items():
        d = np.abs(curve.times - old)
        i = int(np.argmin(d))
        if d[i] <= tol:
            src.append(i)
            dst.append(float(new))
    if not src:
        return curve
    src, dst = np.array(src), np.array(dst)
    moved = np.zeros(len(curve), dtype=bool)
    moved[src] = True
    rest = np.flatnonzero(~moved & ~_key_mask(curve, dst, tol))
    idx = np.r_[rest, src]
    times = np.r_[curve.times[rest], dst]
    shift = times - curve.times[idx]
    order = np.argsort(times, kind="stable")
    idx, times, shift = idx[order], times[order], shift[order]
    keep = np.r_[True, np.diff(times) > tol]   # two moved onto one time: one of them stays
    idx, times, shift = idx[keep], times[keep], shift[keep]
    left, right = curve.left[idx].copy(), curve.right[idx].copy()
    left[:, 0] += shift
    right[:, 0] += shift
    return Curve(times, curve.values[idx], curve.interpolation[idx], left, right,
                 curve.left_type[idx], curve.right_type[idx])
