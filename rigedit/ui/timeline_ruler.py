"""The timeline's ruler widget: time ruler (seconds and frames), key rows and the time cursor.

It only paints and reports mouse gestures as signals; :class:`~rigedit.ui.timeline.TimelineDock`
turns them into document calls.
"""
from __future__ import annotations

import numpy as np
from PyQt5 import QtCore, QtGui, QtWidgets

from ..editor.playback import snap_to_frame
from .cached_paint import cached_picture

__all__ = ["TimelineRuler"]

RULER_H, ROW_H, LEFT, RIGHT = 20, 18, 70, 14
KEY_PICK_PX = 6
CURSOR_W = 3  # pixels each side of the cursor's x repainted when it moves (a 2 px pen, antialiased)


class TimelineRuler(QtWidgets.QWidget):
    """Paints the time ruler (seconds and frames), the key rows and the time cursor; reports
    gestures. Rows: the summary (keys of all joints) and the selected joint's keys.

    Signals
    -------
    scrubbed(float)                  the user asks for a time (press or drag on the ruler)
    key_drag_started(float, bool)    a key at time t was grabbed; bool: all joints (summary)
    key_dragged(float)               the grabbed key's new time (frame-snapped)
    key_drag_finished()
    """

    scrubbed = QtCore.pyqtSignal(float)
    key_drag_started = QtCore.pyqtSignal(float, bool)
    key_dragged = QtCore.pyqtSignal(float)
    key_drag_finished = QtCore.pyqtSignal()

    def __init__(self, parent=None):
        super().__init__(parent)
        self.duration, self.fps, self.time = 1.0, 30.0, 0.0
        self.summary_keys = np.zeros(0)
        self.joint_keys = np.zeros(0)
        self.joint_name = None
        self._drag = None
        self._background = None  # QPixmap of everything but the cursor, or None to repaint
        self.setMinimumHeight(RULER_H + 2 * ROW_H + 6)
        self.setMouseTracking(False)
        self.setFocusPolicy(QtCore.Qt.ClickFocus)

    def set_data(self, duration, fps, time, summary_keys, joint_keys, joint_name):
        """Show these keys and the cursor at ``time``. When only the time changed (each
        playback frame), only the old and the new cursor's strips are repainted, from the
        cached picture of the rest: a whole repaint cost about 1 ms a frame under Xvfb."""
        data = (max(float(duration), 1e-6), float(fps), np.asarray(summary_keys, dtype=float),
                np.asarray(joint_keys, dtype=float), joint_name)
        same = (data[0] == self.duration and data[1] == self.fps and data[4] == self.joint_name
                and np.array_equal(data[2], self.summary_keys)
                and np.array_equal(data[3], self.joint_keys))
        old_x = self.x_of(self.time)
        self.duration, self.fps, self.summary_keys, self.joint_keys, self.joint_name = data
        self.time = float(time)
        if not same:
            self._background = None
            self.update()
        elif self.x_of(self.time) != old_x:
            for x in (old_x, self.x_of(self.time)):
                self.update(self._cursor_rect(x))

    def _cursor_rect(self, x):
        return QtCore.QRect(int(np.floor(x)) - CURSOR_W, 0, 2 * CURSOR_W + 1, self.height())

    def resizeEvent(self, event):
        self._background = None
        super().resizeEvent(event)

    def changeEvent(self, event):
        # the cached picture's colours come from the palette's current group, which
        # follows the window's activation and the enabled state too
        if event.type() in (QtCore.QEvent.PaletteChange, QtCore.QEvent.FontChange,
                            QtCore.QEvent.StyleChange, QtCore.QEvent.ActivationChange,
                            QtCore.QEvent.EnabledChange):
            self._background = None
        super().changeEvent(event)

    # ------------------------------------------------------------------ geometry
    def x_of(self, t):
        return LEFT + t / self.duration * max(self.width() - LEFT - RIGHT, 1)

    def t_of(self, x):
        t = (x - LEFT) / max(self.width() - LEFT - RIGHT, 1) * self.duration
        return float(min(max(snap_to_frame(t, self.fps), 0.0), self.duration))

    def row_y(self, row):
        return RULER_H + 2 + row * ROW_H

    # ------------------------------------------------------------------ painting
    def paintEvent(self, _event):
        self._background = cached_picture(self, self._background, self._paint_background)
        p = QtGui.QPainter(self)
        p.drawPixmap(0, 0, self._background)  # clipped to the repainted region
        p.setRenderHint(QtGui.QPainter.Antialiasing)
        p.setPen(QtGui.QPen(QtGui.QColor("#e04040"), 2))
        x = self.x_of(self.time)
        p.drawLine(QtCore.QPointF(x, 0), QtCore.QPointF(x, self.height()))
        p.end()

    def _paint_background(self, device):
        """Everything but the time cursor: ruler, labels, key rows (cached in a pixmap)."""
        p = QtGui.QPainter(device)
        p.setRenderHint(QtGui.QPainter.Antialiasing)
        w, h = self.width(), self.height()
        pal = self.palette()
        p.fillRect(0, 0, w, h, pal.color(QtGui.QPalette.Base))
        p.fillRect(0, 0, w, RULER_H, pal.color(QtGui.QPalette.Window))
        text = pal.color(QtGui.QPalette.Text)
        mid = pal.color(QtGui.QPalette.Mid)
        # frame ticks: every frame when there is room, else every 5th / 10th
        px_per_frame = (w - LEFT - RIGHT) / max(self.duration * self.fps, 1)
        step = next((s for s in (1, 2, 5, 10, 30, 60, 120) if s * px_per_frame >= 6), 240)
        label_every = next((s for s in (1, 2, 5, 10, 30, 60, 120, 240) if s * px_per_frame >= 45),
                           480)
        n = int(self.duration * self.fps + 1e-9)
        font = p.font()
        font.setPointSizeF(7.5)
        p.setFont(font)
        for f in range(0, n + 1, step):
            x = self.x_of(f / self.fps)
            big = f % label_every == 0
            p.setPen(text if big else mid)
            p.drawLine(QtCore.QPointF(x, RULER_H - (9 if big else 4)), QtCore.QPointF(x, RULER_H))
            if big:
                p.drawText(QtCore.QPointF(x + 2, 9), f"{f}")
                p.drawText(QtCore.QPointF(x + 2, 17), f"{f / self.fps:.2f}s")
        p.setPen(text)
        p.drawText(QtCore.QPointF(4, 9), "frame")
        p.drawText(QtCore.QPointF(4, 17), "seconds")
        rows = (("all joints", self.summary_keys, QtGui.QColor("#e0a030")),
                (self.joint_name or "(no joint)", self.joint_keys, QtGui.QColor("#f0d060")))
        for r, (label, keys, color) in enumerate(rows):
            y = self.row_y(r)
            p.fillRect(QtCore.QRectF(0, y, w, ROW_H - 1),
                       pal.color(QtGui.QPalette.AlternateBase if r % 2 else QtGui.QPalette.Base))
            p.setPen(text)
            p.drawText(QtCore.QRectF(4, y, LEFT - 6, ROW_H), QtCore.Qt.AlignVCenter,
                       p.fontMetrics().elidedText(label, QtCore.Qt.ElideRight, LEFT - 8))
            p.setPen(QtGui.QPen(QtGui.QColor("#303030"), 1))
            p.setBrush(color)
            cy = y + ROW_H / 2
            for t in keys:
                x = self.x_of(t)
                p.drawPolygon(QtGui.QPolygonF([QtCore.QPointF(x, cy - 5), QtCore.QPointF(x + 5, cy),
                                               QtCore.QPointF(x, cy + 5), QtCore.QPointF(x - 5, cy)]))
        p.end()

    # ------------------------------------------------------------------ mouse
    def key_at(self, x, y):
        """(time, all_joints) of the key mark under pixel (x, y), or None."""
        for r, keys in enumerate((self.summary_keys, self.joint_keys)):
            y0 = self.row_y(r)
            if y0 <= y < y0 + ROW_H and len(keys):
                d = np.abs(np.array([self.x_of(t) for t in keys]) - x)
                i = int(np.argmin(d))
                if d[i] <= KEY_PICK_PX:
                    return float(keys[i]), r == 0
        return None

    def mousePressEvent(self, event):
        if event.button() != QtCore.Qt.LeftButton:
            return
        hit = self.key_at(event.x(), event.y())
        if hit is not None:
            self._drag = "key"
            self.key_drag_started.emit(*hit)
        else:
            self._drag = "scrub"
            self.scrubbed.emit(self.t_of(event.x()))

    def mouseMoveEvent(self, event):
        if self._drag == "key":
            self.key_dragged.emit(self.t_of(event.x()))
        elif self._drag == "scrub":
            self.scrubbed.emit(self.t_of(event.x()))

    def mouseReleaseEvent(self, _event):
        if self._drag == "key":
            self.key_drag_finished.emit()
        self._drag = None
