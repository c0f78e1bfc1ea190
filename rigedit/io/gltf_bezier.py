"""Bezier tracks in glTF: CUBICSPLINE where the curves are cubic Hermites in time, else
resampled.

A bezier segment whose handles sit at exactly 1/3 and 2/3 of its duration in time has x(u)
linear in u, so its value is a cubic polynomial in time: a glTF CUBICSPLINE segment with the
Bezier's end derivatives as tangents is the same curve. A linear segment is one too (both
tangents the slope), and so is a constant one whose two keys hold the same value. A vector
track whose three curves are all of these is written as CUBICSPLINE keyed at the union of the
curves' key times, each curve's in- and out-tangent there its derivative from either side
(inside a segment the two are equal: the polynomial is just split). A track whose curves are
all constant segments is written as STEP.

Anything else (rotations, which glTF interpolates as quaternions, not Euler angles; handles at
other time spans; steps mixed with curves) is resampled as LINEAR: the key times plus a
grid at :data:`START_RATE`, each interval whose LINEAR (slerp for rotations) midpoint is
further than :data:`TOLERANCE` from the curve halved, again, until all are within it or an
interval is as short as 1 / (2 :data:`MAX_RATE`); a :class:`BezierResampledWarning` gives the
keys, the densest rate and the error reached.
A constant segment's jump is kept by a key :data:`STEP_GAP` before the next key.
"""
from __future__ import annotations

import warnings

import numpy as np

__all__ = ["bezier_keys", "BezierResampledWarning", "TOLERANCE", "START_RATE", "MAX_RATE",
           "STEP_GAP"]

#: Largest midpoint error of a resampled track: units (metres, scale) or degrees (rotation).
TOLERANCE = {"translation": 1e-4, "scale": 1e-4, "rotation": 0.01}
START_RATE = 30.0
MAX_RATE = 1920.0
#: A constant segment's jump is written as a key this long (seconds) before the next key.
STEP_GAP = 1e-4


class BezierResampledWarning(UserWarning):
    """A bezier track could not be written exactly and was resampled as LINEAR."""


def _hermite_ok(curve):
    """Whether every segment of ``curve`` is a cubic polynomial in time (see the notes)."""
    if len(curve) < 2:
        return True
    seg, code = curve.segments(), curve.codes()[:-1]
    dt = np.diff(curve.times)
    x = seg[:, :, 0]
    thirds = (np.abs(x[:, 1] - x[:, 0] - dt / 3) <= 1e-9 * dt) & \
             (np.abs(x[:, 3] - x[:, 2] - dt / 3) <= 1e-9 * dt)
    flat = seg[:, 0, 1] == seg[:, 3, 1]
    return bool(np.all(np.where(code == 2, thirds, (code == 1) | flat)))


def _derivative(curve, t, side):
    """(N,) d value / d t of a Hermite-expressible curve at times ``t`` from the left
    (``side`` 0) or the right (1); 0 outside the keys (the curve holds its ends)."""
    times = curve.times
    out = np.zeros(len(t))
    if len(times) < 2:
        return out
    pos = np.searchsorted(times, t, side="right" if side else "left") - 1
    inside = (pos >= 0) & (pos < len(times) - 1)
    s = pos[inside]
    seg = curve.segments()[s]
    dt = np.diff(times)[s]
    u = (t[inside] - times[s]) / dt
    y = seg[:, :, 1]
    w = 1 - u
    bez = 3 * (w * w * (y[:, 1] - y[:, 0]) + 2 * u * w * (y[:, 2] - y[:, 1])
               + u * u * (y[:, 3] - y[:, 2])) / dt
    code = curve.codes()[s]
    out[inside] = np.where(code == 2, bez, np.where(code == 1, (y[:, 3] - y[:, 0]) / dt, 0.0))
    return out


def _resampled(track, label):
    """(times, values) of a LINEAR resampling within :data:`TOLERANCE` (see the notes)."""
    keys = track.times
    jumps = [c.times[1:][c.codes()[:-1] == 0] - STEP_GAP for c in track.curves if len(c) > 1]
    jumps = np.concatenate(jumps) if jumps else np.zeros(0)
    tol = TOLERANCE[track.channel]
    n = max(int(np.ceil((keys[-1] - keys[0]) * START_RATE)), 1)
    times = np.unique(np.r_[keys, jumps, np.linspace(keys[0], keys[-1], n + 1)])
    times = times[np.r_[True, np.diff(times) > 1e-7]]
    while True:   # halve the intervals whose midpoint is off, down to 1 / MAX_RATE
        values = track.curve_values(times)
        err, mid = _midpoint_error(track, times, values, jumps)
        split = (err > tol) & (np.diff(times) > 1.0 / MAX_RATE)
        if not split.any():
            break
        times = np.sort(np.r_[times, mid[split]])
    unit = "degrees" if track.channel == "rotation" else "units"
    gaps = np.diff(times)[~np.isin(times[:-1], jumps)]
    where = f"{label} " if label else ""
    warnings.warn(f"glTF: {where}a bezier {track.channel} track resampled as LINEAR: "
                  f"{len(times)} keys, {1 / np.min(gaps, initial=1.0):.0f} Hz at "
                  f"the densest (within {np.max(err, initial=0.0):.2g} {unit} at the "
                  f"intervals' midpoints)", BezierResampledWarning, stacklevel=4)
    return times, values


def _midpoint_error(track, times, values, jumps):
    """(M,) distance between the track and its LINEAR (slerp) interpolation at the (M,)
    midpoints of the sample intervals (0 for intervals ending at a jump), and the
    midpoints."""
    mid = 0.5 * (times[1:] + times[:-1])
    if len(times) < 2:
        return np.zeros(0), mid
    true = track.curve_values(mid)
    if track.channel == "rotation":
        a, b = values[:-1], values[1:]
        b = b * np.where(np.sum(a * b, axis=1) < 0, -1.0, 1.0)[:, None]
        lin = (a + b) / np.linalg.norm(a + b, axis=1, keepdims=True)
        err = np.degrees(2 * np.arccos(np.clip(np.abs(np.sum(lin * true, axis=1)), 0, 1)))
    else:
        err = np.max(np.abs(0.5 * (values[:-1] + values[1:]) - true), axis=1)
    return np.where(np.isin(times[:-1], jumps), 0.0, err), mid


def bezier_keys(track, label=""):
    """glTF sampler data of a bezier track.

    Parameters
    ----------
    track : Track
        A ``bezier`` track.
    label : str
        Names the track in the resampling warning (joint).

    Returns
    -------
    times : (N,) float
    values : (N, C) or (3 N, C) float
        CUBICSPLINE: in-tangent, value, out-tangent per key (per second); else the values.
    kind : {"CUBICSPLINE", "STEP", "LINEAR"}
    """
    curves, times = track.curves, track.times
    if all(np.all(c.codes()[:-1] == 0) for c in curves):
        return times, track.values, "STEP"
    if track.channel != "rotation" and all(_hermite_ok(c) for c in curves):
        tangents = [np.stack([_derivative(c, times, side) for c in curves], axis=1)
                    for side in (0, 1)]
        values = np.stack([tangents[0], track.values, tangents[1]], axis=1)
        return times, values.reshape(-1, track.values.shape[1]), "CUBICSPLINE"
    times, values = _resampled(track, label)
    return times, values, "LINEAR"
