"""Cubic Bezier segments of curves, evaluated in time: the numeric kernel of
:mod:`rigedit.animation.curve`, vectorised over many segments at once.

:func:`bezier_points` gives each segment's control points with the handles' time extents
corrected so that x(u) is monotone; :func:`solve_u` finds u with x(u) = t by safeguarded
Newton steps; :func:`evaluate` samples constant, linear and bezier segments together.
"""
from __future__ import annotations

import numpy as np

__all__ = ["INTERPOLATIONS", "bezier_points", "solve_u", "evaluate"]

#: Per-key interpolation names; :func:`evaluate` takes them or their indices in this tuple.
INTERPOLATIONS = ("constant", "linear", "bezier")


def bezier_points(times, values, left, right):
    """Control points of each segment of a curve, time extents corrected.

    Parameters
    ----------
    times, values : (K,) float
    left, right : (K, 2) float

    Returns
    -------
    points : (K - 1, 4, 2) float
        Per segment: key k, its out-handle, key k + 1's in-handle, key k + 1; the handles
        scaled towards their keys where their time extents overlap (sum over the segment's
        duration), so that x(u) is monotone.
    """
    p0 = np.stack([times[:-1], values[:-1]], axis=1)
    p3 = np.stack([times[1:], values[1:]], axis=1)
    h1 = right[:-1] - p0
    h2 = left[1:] - p3
    dt = p3[:, 0] - p0[:, 0]
    reach = np.maximum(h1[:, 0], 0) - np.minimum(h2[:, 0], 0)
    f = np.where(reach > dt, dt / np.maximum(reach, 1e-300), 1.0)[:, None]
    return np.stack([p0, p0 + h1 * f, p3 + h2 * f, p3], axis=1)


def solve_u(x, t, iterations=30):
    """Parameters u in [0, 1] with ``x(u) = t`` for monotone cubic Beziers.

    Parameters
    ----------
    x : (N, 4) float
        The time control points of each segment.
    t : (N,) float
        Times inside each segment.

    Returns
    -------
    u : (N,) float
        Newton steps from the linear guess, kept inside a shrinking bisection bracket (a step
        leaving it bisects), until every residual is under 1e-12 of the segment's duration.
    """
    x0, x1, x2, x3 = x[:, 0], x[:, 1], x[:, 2], x[:, 3]
    # power basis: x(u) = a u^3 + b u^2 + c u + x0
    c = 3 * (x1 - x0)
    b = 3 * (x2 - 2 * x1 + x0)
    a = x3 - x0 - c - b
    span = np.maximum(x3 - x0, 1e-300)
    u = np.clip((t - x0) / span, 0.0, 1.0)
    lo, hi = np.zeros_like(u), np.ones_like(u)
    tol = 1e-12 * span
    for _ in range(iterations):
        f = ((a * u + b) * u + c) * u + x0 - t
        # a converged sample stays where it is while others iterate: its next Newton step
        # rounds to u itself, which lies on its bracket's edge and would read as leaving it
        # (a bisection would throw the root away to the middle of a wide bracket)
        active = np.abs(f) > tol
        if not active.any():
            break
        lo = np.where(f < 0, u, lo)
        hi = np.where(f > 0, u, hi)
        d = (3 * a * u + 2 * b) * u + c
        with np.errstate(divide="ignore", invalid="ignore"):
            step = u - f / d
        bad = ~np.isfinite(step) | (step <= lo) | (step >= hi)
        u = np.where(active, np.where(bad, 0.5 * (lo + hi), step), u)
    return u


def evaluate(seg, interpolation, t):
    """Values of segments at times inside them.

    Parameters
    ----------
    seg : (N, 4, 2) float
        Control points (:func:`bezier_points`) of the segment each time falls in.
    interpolation : (N,) str or (N,) int
        Names from :data:`INTERPOLATIONS` or their indices.
    t : (N,) float

    Returns
    -------
    values : (N,) float
    """
    code = np.asarray(interpolation)
    if code.dtype == object:
        code = np.array([INTERPOLATIONS.index(n) for n in code], dtype=np.int8)
    p0, p3 = seg[:, 0], seg[:, 3]
    frac = (t - p0[:, 0]) / np.maximum(p3[:, 0] - p0[:, 0], 1e-300)
    out = np.where(t >= p3[:, 0], p3[:, 1], p0[:, 1])        # constant (the last key at its end)
    lin = code == 1
    out[lin] = p0[lin, 1] + (p3[lin, 1] - p0[lin, 1]) * frac[lin]
    bez = code == 2
    if bez.any():
        s = seg[bez]
        u = solve_u(s[:, :, 0], t[bez])
        w = 1 - u
        y = s[:, :, 1]
        out[bez] = (w ** 3 * y[:, 0] + 3 * w * w * u * y[:, 1] + 3 * w * u * u * y[:, 2]
                    + u ** 3 * y[:, 3])
    return out
