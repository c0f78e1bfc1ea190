"""The graph editor's view transform: time (seconds) and value <-> pixels, zoom, pan, framing.

Pure arithmetic on numpy arrays (no Qt), so the canvas, its mouse handling and the tests share
one mapping. Time runs left to right, values bottom to top (pixel y grows downwards).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["ViewTransform", "grid_step"]

#: The smallest spans the view shows (a flat curve or one key still gets a usable scale).
MIN_TIME_SPAN, MIN_VALUE_SPAN = 1e-3, 1e-6
#: The largest spans (a runaway zoom-out stays finite).
MAX_SPAN = 1e7


def grid_step(units_per_px, min_px=40.0):
    """The grid spacing for a scale: the smallest of 1, 2 or 5 times a power of ten that is
    at least ``min_px`` pixels apart.

    Parameters
    ----------
    units_per_px : float
        Data units (seconds, degrees, metres, frames) per pixel.
    min_px : float
        The least distance in pixels between two grid lines.

    Returns
    -------
    float
    """
    want = max(float(units_per_px) * min_px, 1e-12)
    power = 10.0 ** math.floor(math.log10(want))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * power >= want * (1 - 1e-9):
            return m * power
    return 10.0 * power


class ViewTransform:
    """The visible window of the graph, ``[t0, t1] x [v0, v1]``, on a pixel rectangle.

    Parameters
    ----------
    left, top, width, height : float
        The plot rectangle in widget pixels (the area inside the ruler and the value labels).

    Attributes
    ----------
    t0, t1 : float
        The times (s) at the rectangle's left and right edges.
    v0, v1 : float
        The values at the rectangle's bottom and top edges.
    """

    def __init__(self, left=0.0, top=0.0, width=100.0, height=100.0):
        self.t0, self.t1, self.v0, self.v1 = 0.0, 1.0, -1.0, 1.0
        self.set_rect(left, top, width, height)

    def set_rect(self, left, top, width, height):
        """Place the plot on the widget (after a resize); the visible window is kept."""
        self.left, self.top = float(left), float(top)
        self.width, self.height = max(float(width), 1.0), max(float(height), 1.0)

    # ------------------------------------------------------------------ mapping
    @property
    def px_per_s(self):
        return self.width / (self.t1 - self.t0)

    @property
    def px_per_unit(self):
        return self.height / (self.v1 - self.v0)

    def x_of(self, t):
        """Pixel x of time ``t`` (scalar or (N,) array)."""
        return self.left + (np.asarray(t, dtype=float) - self.t0) * self.px_per_s

    def y_of(self, v):
        """Pixel y of value ``v`` (scalar or (N,) array)."""
        return self.top + (self.v1 - np.asarray(v, dtype=float)) * self.px_per_unit

    def t_of(self, x):
        """Time at pixel x (scalar or (N,) array)."""
        return self.t0 + (np.asarray(x, dtype=float) - self.left) / self.px_per_s

    def v_of(self, y):
        """Value at pixel y (scalar or (N,) array)."""
        return self.v1 - (np.asarray(y, dtype=float) - self.top) / self.px_per_unit

    def column_times(self):
        """(W + 1,) the times of the plot's pixel columns, left edge to right edge: where a
        curve is sampled to be drawn (one sample per column)."""
        return self.t_of(self.left + np.arange(int(math.ceil(self.width)) + 1, dtype=float))

    # ------------------------------------------------------------------ changing the window
    def set_window(self, t0, t1, v0, v1):
        """Show ``[t0, t1] x [v0, v1]``; spans below the minimum grow about their centre."""
        self.t0, self.t1 = _span(t0, t1, MIN_TIME_SPAN)
        self.v0, self.v1 = _span(v0, v1, MIN_VALUE_SPAN)

    def zoom(self, factor, x=None, y=None, time=True, value=True):
        """Zoom in by ``factor`` (> 1 zooms in) about pixel (x, y) (the centre when None),
        on the time axis, the value axis or both: the point under the mouse stays put."""
        if time:
            tc = self.t_of(self.left + self.width / 2 if x is None else x)
            self.t0, self.t1 = _span(tc + (self.t0 - tc) / factor, tc + (self.t1 - tc) / factor,
                                     MIN_TIME_SPAN)
        if value:
            vc = self.v_of(self.top + self.height / 2 if y is None else y)
            self.v0, self.v1 = _span(vc + (self.v0 - vc) / factor, vc + (self.v1 - vc) / factor,
                                     MIN_VALUE_SPAN)

    def pan(self, dx, dy):
        """Move the view's content by (dx, dy) pixels (a middle-drag)."""
        dt, dv = dx / self.px_per_s, dy / self.px_per_unit
        self.t0, self.t1 = self.t0 - dt, self.t1 - dt
        self.v0, self.v1 = self.v0 + dv, self.v1 + dv

    def frame(self, times, values, margin=0.08):
        """Fit the view to the points ``(times, values)`` ((N,) arrays) with ``margin`` of
        each span around them. A single time or value gets a span around it; no points
        leave the view as it is.

        Returns
        -------
        bool
            Whether there was anything to frame.
        """
        t = np.asarray(times, dtype=float).ravel()
        v = np.asarray(values, dtype=float).ravel()
        ok = np.isfinite(t) & np.isfinite(v)
        if not ok.any():
            return False
        t, v = t[ok], v[ok]
        t0, t1, v0, v1 = t.min(), t.max(), v.min(), v.max()
        # one key (or keys at one time / one value): a second on each side, a unit of value
        if t1 - t0 < MIN_TIME_SPAN:
            t0, t1 = t0 - 0.5, t1 + 0.5
        if v1 - v0 < 1e-9 * max(1.0, abs(v0)):
            v0, v1 = v0 - 1.0, v1 + 1.0
        mt, mv = (t1 - t0) * margin, (v1 - v0) * margin
        self.set_window(t0 - mt, t1 + mt, v0 - mv, v1 + mv)
        return True


def _span(a, b, least):
    a, b = float(min(a, b)), float(max(a, b))
    c, half = (a + b) / 2, (b - a) / 2
    half = min(max(half, least / 2), MAX_SPAN / 2)
    return c - half, c + half
