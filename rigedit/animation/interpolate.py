"""Keyframe interpolation: the lecture's set, per track.

=================  ==========================  ===========================================
mode               channels                    what it does
=================  ==========================  ===========================================
``step``           all                         holds each key until the next one
``linear``         translation, scale          LERP
``nlerp``          rotation                    normalised LERP on the shortest path
``slerp``          rotation                    spherical LERP, constant angular velocity
``hybrid``         rotation                    NLERP below ``HYBRID_THRESHOLD`` radians
                                               between the two keys, SLERP above
``catmull_rom``    all three                   centripetal Catmull-Rom (alpha = 0.5)
                                               through the keys, C1 in time
``cubic_spline``   all three                   cubic Hermite with an in- and an out-tangent
                                               stored per key (glTF's CUBICSPLINE); rotations
                                               are normalised after, not hemisphere-aligned
=================  ==========================  ===========================================

Every function takes the key arrays of one track and a sample time and returns the value; the
keys are assumed validated by :class:`rigedit.animation.clip.Track` (sorted times, unit
quaternions on one hemisphere between neighbours).

Catmull-Rom on rotations
------------------------
Rotations use the same spline as vectors, on the hemisphere-aligned quaternions seen as points
of R^4, and the result is normalised. Chosen over ``scipy``'s ``RotationSpline`` because it is
*local* (a key edit changes only the four segments around it, as an animator expects from a
Catmull-Rom), it passes through every key, it shares one code path and one set of tangents with
translation, and it costs one cubic per sample with baked tangents. ``RotationSpline`` is a
global C2 spline in rotation-vector space: smoother, but editing one key moves the whole curve
and it overshoots more on sparse keys. Normalisation keeps the curve C1 because the
un-normalised curve stays far from the origin for aligned keys less than ~180 degrees apart.

Centripetal knots and time
--------------------------
Centripetal Catmull-Rom spaces its knots by the square root of the chord length between keys
(no cusps or self-intersections inside a segment). Played back in *time*, a spline that is C1
in its knot parameter is only G1 in time when keys are not spaced in proportion to those
knots. So the tangent at each key is the centripetal one (Barry-Goldman closed form), converted
to units per second with the knot-per-second rate of its two neighbouring segments, and each
segment is a cubic Hermite in time: the curve passes through the keys and its velocity is
continuous in time. With knots proportional to key times this is exactly the centripetal
Catmull-Rom. End keys use the secant slope (a reflected phantom key), except on a closed track
(last key equal to the first, as looping clips have), whose ends take the tangent through the
wrap-around neighbours so the loop point is C1 as well.
"""
from __future__ import annotations

import numpy as np

__all__ = ["MODES", "VECTOR_MODES", "ROTATION_MODES", "HYBRID_THRESHOLD", "segment",
           "sample_track", "sample_many", "lerp", "nlerp", "slerp", "hybrid",
           "catmull_rom_tangents", "hermite"]

VECTOR_MODES = ("step", "linear", "catmull_rom", "cubic_spline")
ROTATION_MODES = ("step", "nlerp", "slerp", "hybrid", "catmull_rom", "cubic_spline")
MODES = tuple(dict.fromkeys(VECTOR_MODES + ROTATION_MODES))

#: Rotation angle between two keys (radians) above which ``hybrid`` uses SLERP. Below 30
#: degrees NLERP's angular-velocity error is under 2% and its path is the same great arc, so the
#: cheaper formula is indistinguishable; above it the speed-up in the middle of the segment
#: shows.
HYBRID_THRESHOLD = np.radians(30.0)

ALPHA = 0.5  # centripetal


def segment(times, t):
    """Key interval of time ``t``: indices ``i``, ``k`` and fraction ``u`` in [0, 1] between
    keys ``i`` and ``k = i + 1`` (clamped at both ends, where ``k`` is ``i``)."""
    n = len(times)
    if n == 1 or t <= times[0]:
        return 0, 0, 0.0
    if t >= times[-1]:
        return n - 1, n - 1, 0.0
    i = int(np.searchsorted(times, t, side="right")) - 1
    span = times[i + 1] - times[i]
    return i, i + 1, float((t - times[i]) / span)


def lerp(a, b, u):
    """Linear interpolation of (C,) vectors."""
    return a + (b - a) * u


def nlerp(a, b, u):
    """Normalised LERP of unit quaternions, on the shortest path (``b`` flipped to ``a``'s
    hemisphere)."""
    if np.dot(a, b) < 0:
        b = -b
    q = a + (b - a) * u
    return q / np.linalg.norm(q)


def slerp(a, b, u):
    """Spherical linear interpolation on the shortest path, constant angular velocity.

    Written by hand because ``scipy.spatial.transform.Slerp`` builds an object per segment
    (about 40 µs each), which dominates a per-frame, per-joint call.
    """
    d = float(np.dot(a, b))
    if d < 0:
        b, d = -b, -d
    if d > 1.0 - 1e-10:  # nearly parallel (under ~1e-5 rad): the sine ratio is ill-conditioned,
        # NLERP equals SLERP there to ~1e-15 (a looser switch, 0.9995, erred by ~1e-5)
        q = a + (b - a) * u
        return q / np.linalg.norm(q)
    theta = np.arccos(d)
    s = np.sin(theta)
    return (np.sin((1 - u) * theta) / s) * a + (np.sin(u * theta) / s) * b


def hybrid(a, b, u, threshold=HYBRID_THRESHOLD):
    """The lecture's hybrid: NLERP when the keys are less than ``threshold`` radians apart (as a
    rotation angle), SLERP otherwise. Hand-written: no library offers the switch."""
    # rotation angle = 2 acos |a.b|; compare cosines to avoid the arccos on the cheap path
    if abs(float(np.dot(a, b))) >= np.cos(threshold / 2):
        return nlerp(a, b, u)
    return slerp(a, b, u)


def catmull_rom_tangents(times, values, alpha=ALPHA):
    """Per-key velocities (units per second) of the centripetal Catmull-Rom through the keys.

    Parameters
    ----------
    times : (K,) float64, strictly increasing
    values : (K, C) float64
        Points; quaternions must already be hemisphere-aligned with their predecessor.
    alpha : float
        0.5 is centripetal, 0 uniform, 1 chordal.

    Returns
    -------
    tangents : (K, C) float64
        d value / d t at each key, used by :func:`hermite` (see the module notes).
    """
    times = np.asarray(times, dtype=np.float64)
    p = np.asarray(values, dtype=np.float64)
    k = len(times)
    out = np.zeros_like(p)
    if k < 2:
        return out
    dp = np.diff(p, axis=0)                                   # (K-1, C)
    dt = np.diff(times)                                       # (K-1,)
    # knot spacing; a floor keeps repeated values (a hold) finite: their chord is ~0 anyway
    dk = np.maximum(np.linalg.norm(dp, axis=1) ** alpha, 1e-9)
    out[0] = dp[0] / dt[0]
    out[-1] = dp[-1] / dt[-1]
    if k > 2:
        d0, d1 = dk[:-1, None], dk[1:, None]
        # Barry-Goldman: derivative at the middle knot w.r.t. the knot parameter
        m = dp[:-1] / d0 - (dp[:-1] + dp[1:]) / (d0 + d1) + dp[1:] / d1
        rate = (d0 + d1) / (dt[:-1, None] + dt[1:, None])    # knots per second around the key
        out[1:-1] = m * rate
        if np.allclose(p[0], p[-1], atol=1e-9, rtol=0):
            # A closed track (last key = first key, as in a looping clip): the ends get the
            # tangent through the wrap-around neighbours, so the loop point is C1 too.
            d0, d1 = dk[-1], dk[0]
            m = dp[-1] / d0 - (dp[-1] + dp[0]) / (d0 + d1) + dp[0] / d1
            out[0] = out[-1] = m * (d0 + d1) / (dt[-1] + dt[0])
    return out


def hermite(p0, p1, m0, m1, dt, u):
    """Cubic Hermite between ``p0`` and ``p1`` with velocities ``m0``, ``m1`` (per second) over
    a segment ``dt`` seconds long, at fraction ``u``."""
    u2 = u * u
    u3 = u2 * u
    h00 = 2 * u3 - 3 * u2 + 1
    h10 = u3 - 2 * u2 + u
    h01 = -2 * u3 + 3 * u2
    h11 = u3 - u2
    return h00 * p0 + h01 * p1 + (h10 * dt) * m0 + (h11 * dt) * m1


_ROT = {"nlerp": nlerp, "slerp": slerp, "hybrid": hybrid, "linear": nlerp}


def sample_track(times, values, t, mode, rotation, tangents=None):
    """Value of a track at time ``t``.

    Parameters
    ----------
    times : (K,) float64, sorted
    values : (K, C) float64
    t : float
    mode : str, one of ``MODES``
    rotation : bool
        Quaternion track (C = 4) or vector track.
    tangents : (K, C) or (K, 2, C) float64, optional
        Baked :func:`catmull_rom_tangents` for ``catmull_rom`` (computed when omitted); for
        ``cubic_spline`` (required) the in-tangent ``[:, 0]`` and out-tangent ``[:, 1]`` of
        each key, in units per second.

    Returns
    -------
    value : (C,) float64
    """
    i, k, u = segment(times, t)
    if i == k or mode == "step":
        if rotation and mode == "cubic_spline":  # keys kept as given, maybe not unit
            return values[i] / np.linalg.norm(values[i])
        return values[i].copy()
    if mode == "cubic_spline":
        # glTF's CUBICSPLINE: the out-tangent of key i and the in-tangent of key k, scaled by
        # the segment length (the tangents are per second).
        q = hermite(values[i], values[k], tangents[i, 1], tangents[k, 0], times[k] - times[i], u)
        return q / np.linalg.norm(q) if rotation else q
    if mode == "catmull_rom":
        if tangents is None:
            lo, hi = max(i - 1, 0), min(k + 2, len(times))
            tangents = np.zeros_like(values)
            tangents[lo:hi] = catmull_rom_tangents(times[lo:hi], values[lo:hi])
            # the window's end keys got secant slopes; only keys i and k matter and they are
            # interior to the window unless they are the track's real ends
        q = hermite(values[i], values[k], tangents[i], tangents[k], times[k] - times[i], u)
        return q / np.linalg.norm(q) if rotation else q
    if rotation:
        return _ROT[mode](values[i], values[k], u)
    return lerp(values[i], values[k], u)


def sample_many(times, values, ts, mode, rotation, tangents=None):
    """Values of a track at many times at once: :func:`sample_track` vectorised.

    Parameters
    ----------
    times : (K,) float64, sorted
    values : (K, C) float64
    ts : (N,) float
    mode, rotation, tangents
        As for :func:`sample_track` (``catmull_rom`` needs its baked tangents here).

    Returns
    -------
    values : (N, C) float64
    """
    ts = np.clip(np.asarray(ts, dtype=np.float64).reshape(-1), times[0], times[-1])
    if len(times) == 1:
        out = np.repeat(values[:1], len(ts), axis=0)
        return out / np.linalg.norm(out, axis=1, keepdims=True) if rotation else out
    i = np.clip(np.searchsorted(times, ts, side="right") - 1, 0, len(times) - 2)
    dt = times[i + 1] - times[i]
    u = ((ts - times[i]) / dt)[:, None]
    a, b = values[i], values[i + 1]
    if mode == "step":
        out = np.where(u >= 1, b, a)
    elif mode in ("catmull_rom", "cubic_spline"):
        m0 = tangents[i] if mode == "catmull_rom" else tangents[i, 1]
        m1 = tangents[i + 1] if mode == "catmull_rom" else tangents[i + 1, 0]
        out = hermite(a, b, m0, m1, dt[:, None], u)
    elif not rotation:
        out = a + (b - a) * u
    else:
        d = np.sum(a * b, axis=1, keepdims=True)
        b, d = np.where(d < 0, -b, b), np.abs(d)
        out = a + (b - a) * u                                   # nlerp, normalised below
        theta = np.arccos(np.clip(d, -1, 1))
        use = d[:, 0] <= 1.0 - 1e-10
        if mode == "hybrid":
            use &= 2 * theta[:, 0] > HYBRID_THRESHOLD
        elif mode not in ("slerp",):
            use[:] = False
        if use.any():
            s = np.sin(theta[use])
            out[use] = (np.sin((1 - u[use]) * theta[use]) / s) * a[use] \
                + (np.sin(u[use] * theta[use]) / s) * b[use]
    if rotation:
        out = out / np.linalg.norm(out, axis=1, keepdims=True)
    return out
