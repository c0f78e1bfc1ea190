"""Where a curve's automatic handles go (:mod:`rigedit.animation.curve`'s handle types).

``auto`` takes the slope of the line through the key's two neighbours; ``auto_clamped`` the
same, flat where the key is a local extreme and limited so each handle stays within the values
of the key and its neighbour (a Bezier lies inside its control points: no overshoot); both
flat at the end keys (the curve holds its end values beyond them). ``vector`` points a third
of the way to the neighbouring key. Each handle is a third of its segment long in time.
"""
from __future__ import annotations

import numpy as np

__all__ = ["ONE_KEY_HANDLE", "spans", "auto_slopes", "place_handles"]

#: Time length (seconds) of the handles of a key without neighbours.
ONE_KEY_HANDLE = 1.0 / 3.0


def spans(times):
    """(K,) time spans before and after each key (the other side's at an end key;
    :data:`ONE_KEY_HANDLE` for a lone key)."""
    if len(times) == 1:
        one = np.array([ONE_KEY_HANDLE])
        return one, one
    dt = np.diff(times)
    return np.r_[dt[0], dt], np.r_[dt, dt[-1]]


def auto_slopes(times, values, clamped):
    """(K,) value-per-second slopes of the automatic handles: the neighbours' secant
    (``auto``), flattened at extremes and limited so the handles stay within the
    neighbouring keys' values (``clamped``); 0 at the end keys."""
    t, v = times, values
    m = np.zeros(len(t))
    if len(t) < 3:
        return m
    dv_a, dv_b = v[1:-1] - v[:-2], v[2:] - v[1:-1]
    dt_a, dt_b = t[1:-1] - t[:-2], t[2:] - t[1:-1]
    inner = (v[2:] - v[:-2]) / (t[2:] - t[:-2])
    if clamped:
        extreme = dv_a * dv_b <= 0
        # a handle a third of the span long reaches m * span / 3: within the key's
        # neighbour when |m| <= 3 |dv| / span, on both sides
        limit = np.minimum(3 * np.abs(dv_a) / dt_a, 3 * np.abs(dv_b) / dt_b)
        inner = np.where(extreme, 0.0, np.clip(inner, -limit, limit))
    m[1:-1] = inner
    return m


def place_handles(times, values, left, right, left_type, right_type):
    """Set the automatic handles of ``left`` and ``right`` ((K, 2), absolute time and value,
    written in place) from their types ((K,) names)."""
    t, v = times, values
    before, after = spans(times)
    slope = {"auto": auto_slopes(t, v, False), "auto_clamped": auto_slopes(t, v, True)}
    prev_v = np.r_[v[0], v[:-1]]
    next_v = np.r_[v[1:], v[-1]]
    for pts, types, span, sign, other in ((left, left_type, before, -1, prev_v),
                                          (right, right_type, after, 1, next_v)):
        for name, m in slope.items():
            mask = types == name
            pts[mask, 0] = t[mask] + sign * span[mask] / 3
            pts[mask, 1] = v[mask] + sign * m[mask] * span[mask] / 3
        mask = types == "vector"
        pts[mask, 0] = t[mask] + sign * span[mask] / 3
        pts[mask, 1] = v[mask] + (other[mask] - v[mask]) / 3
