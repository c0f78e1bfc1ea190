"""The graph editor's canvas: channels' curves over time, painted with QPainter.

It only paints what it is given (channels, which are shown, the selected keys, the time
cursor, a rubber band) and maps between pixels and (time, value) through its
:class:`~.graph_transform.ViewTransform`; :mod:`.graph_interaction` turns the mouse and keys
into edits. A channel here is a :class:`rigedit.editor.graph_commands.ChannelView` (``id``,
``colour``, ``curve`` with ``times``, ``values``, ``interpolation``, ``left``, ``right``, and
``sample(times)``, what the channel plays).

Cost: a curve is drawn as one polyline sampled once per pixel column (``sample`` on (W,)
times), keys as one ``drawPoints`` call per channel from numpy through the polygon's buffer
(no Python object per key), only the keys in the visible time range; where neighbouring keys
are closer than :data:`DENSE_PX` pixels (a mocap clip: a key per frame) they are drawn as
small touching squares, one per pixel, which read as a thick line along the curve. Everything
but the time cursor is cached in a pixmap, so playback (the cursor moving) repaints two thin
strips, as the timeline does. ``benchmarks/bench_graph_paint.py`` measures a repaint: 3
channels of 100,000 keys in 58 ms, 1/75 of drawing each key with its own call.
"""
from __future__ import annotations

import numpy as np
from PyQt5 import QtCore, QtGui, QtWidgets

from .cached_paint import cached_picture
from .graph_transform import ViewTransform, grid_step

__all__ = ["GraphView", "polygon", "DENSE_PX"]

RULER_H, LEFT, RIGHT, BOTTOM = 20, 52, 10, 6
#: Keys closer than this (pixels) to a neighbour are drawn as a line, not as points.
DENSE_PX = 4.0
KEY_PX, DENSE_KEY_PX, SELECTED_PX, HANDLE_PX = 5.0, 3.0, 7.0, 6.0
CURSOR_W = 3
SELECTED = QtGui.QColor("#ffb347")
HANDLE_LINE = QtGui.QColor(200, 200, 200, 170)
CURSOR = QtGui.QColor("#e04040")


def polygon(xs, ys):
    """A QPolygonF of the points ``(xs[i], ys[i])`` written through its buffer (no QPointF
    per point).

    Parameters
    ----------
    xs, ys : (N,) array_like of float
    """
    n = len(xs)
    poly = QtGui.QPolygonF(n)
    if n:
        buf = poly.data()
        buf.setsize(16 * n)   # QPointF: two doubles
        pts = np.frombuffer(buf, dtype=np.float64).reshape(n, 2)
        pts[:, 0] = xs
        pts[:, 1] = ys
    return poly


def _colour(rgb, alpha=255):
    r, g, b = (int(round(255 * min(max(float(c), 0.0), 1.0))) for c in rgb[:3])
    return QtGui.QColor(r, g, b, alpha)


def dense_mask(xs, ys, gap=DENSE_PX):
    """(N,) bool: the keys at pixels (xs, ys) that are closer than ``gap`` to a neighbour."""
    n = len(xs)
    close = np.hypot(np.diff(xs), np.diff(ys)) < gap if n > 1 else np.zeros(0, dtype=bool)
    dense = np.zeros(n, dtype=bool)
    dense[:-1] |= close
    dense[1:] |= close
    return dense


class GraphView(QtWidgets.QWidget):
    """The canvas. Scripts and :mod:`.graph_interaction` set its state and call
    :meth:`update_view` (everything) or :meth:`set_time` (the cursor only).

    Parameters
    ----------
    fps : callable
        () -> the frame rate of the ruler's frame numbers (the timeline's).

    Attributes
    ----------
    transform : ViewTransform
    channels : list of ChannelView
        All channels of the selected joints, shown or not.
    hidden : set of ChannelId
        The channels not drawn (and not hit).
    selected : dict
        ChannelId -> (n,) sorted int array of selected key indices.
    time, duration : float
        The time cursor and the clip's length (seconds); outside ``[0, duration]`` is shaded.
    rubber_band : QRectF or None
        The box selection being dragged.
    message : str
        Shown in the middle when there is no channel (why the graph is empty).
    """

    #: The selected keys changed (read :attr:`selected`).
    selection_changed = QtCore.pyqtSignal()

    def __init__(self, fps, parent=None):
        super().__init__(parent)
        self.fps = fps
        self.transform = ViewTransform()
        self.channels, self.hidden, self.selected = [], set(), {}
        self.time, self.duration = 0.0, 1.0
        self.rubber_band = None
        self.message = ""
        self._background = None
        self.setMinimumSize(240, 120)
        self.setFocusPolicy(QtCore.Qt.StrongFocus)

    # ------------------------------------------------------------------ state
    def visible_channels(self):
        """The channels drawn (not hidden, with a curve), in list order."""
        return [c for c in self.channels if c.curve is not None and c.id not in self.hidden]

    def set_channels(self, channels):
        """Show ``channels``; selected keys of channels no longer there are dropped."""
        self.channels = list(channels)
        count = {c.id: len(c.curve.times) for c in self.channels if c.curve is not None}
        kept = {k: v[v < count[k]] for k, v in self.selected.items() if k in count}
        self.selected = {k: v for k, v in kept.items() if len(v)}
        self.update_view()

    def set_selection(self, selected):
        """Select keys: ChannelId -> indices (empty entries dropped)."""
        self.selected = {k: np.unique(np.asarray(v, dtype=int)) for k, v in selected.items()
                         if len(v)}
        self.update_view()
        self.selection_changed.emit()

    def selection_count(self):
        return int(sum(len(v) for v in self.selected.values()))

    def update_view(self):
        """Repaint everything (the data or the window changed)."""
        self._background = None
        self.update()

    def set_time(self, t):
        """Move the time cursor; only its old and new strips are repainted."""
        old = float(self.transform.x_of(self.time))
        self.time = float(t)
        new = float(self.transform.x_of(self.time))
        if old != new:
            for x in (old, new):
                self.update(QtCore.QRect(int(np.floor(x)) - CURSOR_W, 0, 2 * CURSOR_W + 1,
                                         self.height()))

    # ------------------------------------------------------------------ framing
    def frame_all(self):
        """Fit every shown channel's keys and the clip's range into the view."""
        curves = [c.curve for c in self.visible_channels()]
        self._frame([np.array([0.0, self.duration])] + [cv.times for cv in curves],
                    [cv.values for cv in curves])

    def frame_selected(self):
        """Fit the selected keys with their drawn handles; all keys when none is selected."""
        times, values = [], []
        for c in self.visible_channels():
            idx = self.selected.get(c.id)
            if idx is None or not len(idx):
                continue
            times.append(c.curve.times[idx])
            values.append(c.curve.values[idx])
            sides = self.handle_sides(c)
            if sides is not None:
                times.append(sides[1][:, 0])
                values.append(sides[1][:, 1])
        if not times:
            self.frame_all()
            return
        self._frame(times, values)

    def _frame(self, times, values):
        """Fit the time range of ``times`` and the value range of ``values`` (lists of
        arrays; no values: -1..1)."""
        t = np.concatenate(times)
        v = np.concatenate(values) if values else np.zeros(0)
        v = v if len(v) else np.array([-1.0, 1.0])
        self._place()
        # frame() takes points: the corners of the two ranges are enough
        self.transform.frame([t.min(), t.max()], [v.min(), v.max()])
        self.update_view()

    # ------------------------------------------------------------------ geometry
    def plot_rect(self):
        """The plot area (inside the ruler and the value labels)."""
        return QtCore.QRectF(LEFT, RULER_H, max(self.width() - LEFT - RIGHT, 1),
                             max(self.height() - RULER_H - BOTTOM, 1))

    def in_ruler(self, pos):
        """Whether widget point ``pos`` is on the time ruler (a click there sets the time)."""
        return pos.y() < RULER_H

    def _place(self):
        r = self.plot_rect()
        self.transform.set_rect(r.left(), r.top(), r.width(), r.height())

    def resizeEvent(self, event):
        self._place()
        self._background = None
        super().resizeEvent(event)

    def showEvent(self, event):
        self._place()
        super().showEvent(event)

    def changeEvent(self, event):
        if event.type() in (QtCore.QEvent.PaletteChange, QtCore.QEvent.FontChange,
                            QtCore.QEvent.StyleChange, QtCore.QEvent.EnabledChange):
            self._background = None
        super().changeEvent(event)

    def visible_keys(self, channel, pad=0.0):
        """The keys of ``channel`` in the visible time range (``pad`` pixels wider).

        Returns
        -------
        index : (n,) int
            Their indices in the curve.
        xs, ys : (n,) float
            Their pixel positions.
        """
        cv, tr = channel.curve, self.transform
        lo = np.searchsorted(cv.times, float(tr.t_of(tr.left - pad)), side="left")
        hi = np.searchsorted(cv.times, float(tr.t_of(tr.left + tr.width + pad)), side="right")
        index = np.arange(lo, hi)
        return index, tr.x_of(cv.times[lo:hi]), tr.y_of(cv.values[lo:hi])

    # ------------------------------------------------------------------ painting
    def paintEvent(self, _event):
        self._background = cached_picture(self, self._background, self._paint_background)
        p = QtGui.QPainter(self)
        p.drawPixmap(0, 0, self._background)
        x = float(self.transform.x_of(self.time))
        p.setPen(QtGui.QPen(CURSOR, 2))
        p.drawLine(QtCore.QPointF(x, 0), QtCore.QPointF(x, self.height()))
        if self.rubber_band is not None:
            p.setPen(QtGui.QPen(QtGui.QColor(255, 255, 255, 200), 1, QtCore.Qt.DashLine))
            p.setBrush(QtGui.QColor(120, 160, 230, 40))
            p.drawRect(self.rubber_band)
        p.end()

    def _paint_background(self, device):
        """Everything but the cursor and the rubber band (cached)."""
        self._place()
        p = QtGui.QPainter(device)
        pal = self.palette()
        p.fillRect(0, 0, self.width(), self.height(), pal.color(QtGui.QPalette.Base))
        plot = self.plot_rect()
        self._paint_clip_range(p, plot, pal)
        self._paint_grid(p, plot, pal)
        p.setClipRect(plot)
        p.setRenderHint(QtGui.QPainter.Antialiasing)
        channels = self.visible_channels()
        times = self.transform.column_times()
        for c in channels:
            self._paint_curve(p, c, times)
        for c in channels:
            self._paint_keys(p, c)
        for c in channels:
            self._paint_handles(p, c)
        p.setClipping(False)
        if not channels and self.message:
            p.setPen(pal.color(QtGui.QPalette.Text))
            p.drawText(plot, QtCore.Qt.AlignCenter, self.message)
        p.end()

    def _paint_clip_range(self, p, plot, pal):
        """Outside the clip ``[0, duration]`` a darker shade."""
        tr = self.transform
        x0, x1 = float(tr.x_of(0.0)), float(tr.x_of(self.duration))
        shade = pal.color(QtGui.QPalette.Base).darker(135)
        if x0 > plot.left():
            p.fillRect(QtCore.QRectF(plot.left(), plot.top(), x0 - plot.left(), plot.height()),
                       shade)
        if x1 < plot.right():
            p.fillRect(QtCore.QRectF(x1, plot.top(), plot.right() - x1, plot.height()), shade)

    def _paint_grid(self, p, plot, pal):
        """Frame lines with their numbers on the ruler; value lines with labels at left."""
        tr, fps = self.transform, max(float(self.fps()), 1e-6)
        text, mid = pal.color(QtGui.QPalette.Text), pal.color(QtGui.QPalette.Mid)
        grid = QtGui.QColor(mid)
        grid.setAlpha(90)
        font = p.font()
        font.setPointSizeF(7.5)
        p.setFont(font)
        p.fillRect(QtCore.QRectF(0, 0, self.width(), RULER_H), pal.color(QtGui.QPalette.Window))
        # time: in frames, at least one frame apart
        step = max(grid_step(fps / tr.px_per_s, 50.0), 1.0)
        f0 = np.ceil(tr.t0 * fps / step) * step
        for f in np.arange(f0, tr.t1 * fps + 1e-9, step):
            x = float(tr.x_of(f / fps))
            p.setPen(grid)
            p.drawLine(QtCore.QPointF(x, plot.top()), QtCore.QPointF(x, plot.bottom()))
            p.setPen(text)
            p.drawLine(QtCore.QPointF(x, RULER_H - 6), QtCore.QPointF(x, RULER_H))
            p.drawText(QtCore.QPointF(x + 2, 12), f"{int(round(f))}")
        # values
        vstep = grid_step(1.0 / tr.px_per_unit, 28.0)
        decimals = max(0, -int(np.floor(np.log10(vstep) + 1e-9)))
        for v in np.arange(np.ceil(tr.v0 / vstep) * vstep, tr.v1 + 1e-12, vstep):
            y = float(tr.y_of(v))
            zero = abs(v) < vstep * 1e-6
            p.setPen(QtGui.QPen(mid if zero else grid, 1))
            p.drawLine(QtCore.QPointF(plot.left(), y), QtCore.QPointF(plot.right(), y))
            p.setPen(text)
            label = f"{0.0 if zero else v:.{decimals}f}"
            p.drawText(QtCore.QRectF(0, y - 7, LEFT - 4, 14),
                       QtCore.Qt.AlignRight | QtCore.Qt.AlignVCenter, label)

    def _paint_curve(self, p, channel, times):
        values = np.asarray(channel.sample(times), dtype=float)
        # 1 px: a wider antialiased polyline of a noisy 1,000-column curve cost ~40 ms
        # under Xvfb, 1 px ~1 ms
        p.setPen(QtGui.QPen(_colour(channel.colour), 1.0))
        p.drawPolyline(polygon(self.transform.x_of(times), self.transform.y_of(values)))

    def _paint_keys(self, p, channel):
        index, xs, ys = self.visible_keys(channel, pad=KEY_PX)
        if not len(index):
            return
        colour = _colour(channel.colour).lighter(130)
        dense = dense_mask(xs, ys)
        if dense.any():
            # close keys: small squares that touch along the curve, so they read as a thick
            # line; a key on the same pixel as the one before is not drawn again (keys are
            # in time order, so this is one pass, no sort). Square points cost ~1 ms per
            # 1,000 where a 3 px antialiased polyline cost ~40 ms (measured under Xvfb)
            dx, dy = np.round(xs[dense]), np.round(ys[dense])
            new = np.ones(len(dx), dtype=bool)
            new[1:] = (dx[1:] != dx[:-1]) | (dy[1:] != dy[:-1])
            p.setRenderHint(QtGui.QPainter.Antialiasing, False)
            p.setPen(QtGui.QPen(colour, DENSE_KEY_PX, QtCore.Qt.SolidLine, QtCore.Qt.SquareCap))
            p.drawPoints(polygon(dx[new], dy[new]))
            p.setRenderHint(QtGui.QPainter.Antialiasing, True)
        lone = ~dense
        p.setPen(QtGui.QPen(colour, KEY_PX, QtCore.Qt.SolidLine, QtCore.Qt.SquareCap))
        p.drawPoints(polygon(xs[lone], ys[lone]))
        sel = self.selected.get(channel.id)
        if sel is not None and len(sel):
            on = np.isin(index, sel)
            p.setPen(QtGui.QPen(SELECTED, SELECTED_PX, QtCore.Qt.SolidLine, QtCore.Qt.SquareCap))
            p.drawPoints(polygon(xs[on], ys[on]))

    def _paint_handles(self, p, channel):
        """The selected keys' handles on the sides with a Bezier segment."""
        sides = self.handle_sides(channel)
        if sides is None:
            return
        keys, handles, _, _ = sides
        tr = self.transform
        kx, ky = tr.x_of(keys[:, 0]), tr.y_of(keys[:, 1])
        hx, hy = tr.x_of(handles[:, 0]), tr.y_of(handles[:, 1])
        p.setPen(QtGui.QPen(HANDLE_LINE, 1.0))
        p.drawLines(polygon(np.column_stack([kx, hx]).ravel(), np.column_stack([ky, hy]).ravel()))
        p.setPen(QtGui.QPen(SELECTED, HANDLE_PX, QtCore.Qt.SolidLine, QtCore.Qt.RoundCap))
        p.drawPoints(polygon(hx, hy))

    def handle_sides(self, channel):
        """The drawn handles of ``channel``'s selected keys: None, or ``(keys, handles,
        index, side)`` arrays: (n, 2) key points, (n, 2) handle points, (n,) key indices and
        (n,) 0 = left / 1 = right. A left handle is shown where the segment before the key
        is Bezier, a right one where the key's own segment is."""
        sel = self.selected.get(channel.id)
        cv = channel.curve
        if sel is None or not len(sel) or cv is None:
            return None
        interp = np.asarray(cv.interpolation, dtype=object)
        bez = interp == "bezier"
        k = len(cv.times)
        left_ok = (sel > 0) & bez[np.maximum(sel - 1, 0)]
        right_ok = (sel < k - 1) & bez[sel]
        index = np.concatenate([sel[left_ok], sel[right_ok]])
        side = np.concatenate([np.zeros(left_ok.sum(), int), np.ones(right_ok.sum(), int)])
        if not len(index):
            return None
        keys = np.column_stack([cv.times[index], cv.values[index]])
        handles = np.where(side[:, None] == 0, cv.left[index], cv.right[index])
        return keys, handles, index, side
