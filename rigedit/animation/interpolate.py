"""Keyframe interpolation: LERP for vectors, NLERP/SLERP on the shortest path for rotations.

Every function takes the key arrays of one track and a sample time and returns the value; the
keys are assumed validated by :class:`rigedit.animation.clip.Track` (sorted times, unit
quaternions on one hemisphere between neighbours).
"""
from __future__ import annotations

import numpy as np

__all__ = ["MODES", "VECTOR_MODES", "ROTATION_MODES", "segment", "sample_track",
           "lerp", "nlerp", "slerp"]

VECTOR_MODES = ("step", "linear")
ROTATION_MODES = ("step", "nlerp", "slerp")
MODES = tuple(dict.fromkeys(VECTOR_MODES + ROTATION_MODES))


def segment(times, t):
    """Key interval of time ``t``: index ``i`` and fraction ``u`` in [0, 1] between keys ``i``
    and ``i + 1`` (clamped at both ends; ``i + 1`` is ``i`` for a single key)."""
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
    if d > 0.9995:  # nearly parallel: the sine ratio is ill-conditioned, NLERP is exact enough
        q = a + (b - a) * u
        return q / np.linalg.norm(q)
    theta = np.arccos(d)
    s = np.sin(theta)
    return (np.sin((1 - u) * theta) / s) * a + (np.sin(u * theta) / s) * b


_ROT = {"nlerp": nlerp, "slerp": slerp, "linear": nlerp}


def sample_track(times, values, t, mode, rotation):
    """Value of a track at time ``t``.

    Parameters
    ----------
    times : (K,) float64, sorted
    values : (K, C) float64
    t : float
    mode : str, one of ``MODES``
    rotation : bool
        Quaternion track (C = 4) or vector track.

    Returns
    -------
    value : (C,) float64
    """
    i, k, u = segment(times, t)
    if i == k or mode == "step":
        return values[i].copy()
    if rotation:
        return _ROT[mode](values[i], values[k], u)
    return lerp(values[i], values[k], u)
