"""The graph editor's mouse and keys: selection, key and handle drags, scaling, framing.

:class:`GraphInteraction` filters the canvas's (:class:`~.graph_view.GraphView`) input events
(the gesture in progress is one of :mod:`.graph_gestures`) and turns them into the editor's
graph commands (:mod:`rigedit.editor.graph_commands`). Every
edit is one undo step: a drag (keys, a handle, an S scale) runs through one ``CurveDrag``
(live updates, one step at the release); Delete, I and the tool row's edits are one command
each. The document then emits ``KeysChanged`` and the dock shows the clip again, as do the 3D
view and the timeline.

=====================  ==========================================================
gesture                what
=====================  ==========================================================
click a key            select it (Shift: add / remove)
drag on empty space    box selection (Shift: add)
drag a selected key    move the selected keys in time (whole frames; Ctrl: free) and value
drag a handle          move it (an auto handle becomes aligned)
S                      scale the selected keys' times about the time cursor (move the
                       mouse, click or Enter to finish; Esc or right-click cancels)
Delete / X             delete the selected keys
I                      a key on every shown channel at the time cursor
A                      select every shown key
Home, F                frame all, frame the selected keys
wheel                  zoom time (Ctrl: the value axis) about the mouse
middle-drag            pan
click the ruler        set the time cursor (drag to scrub)
=====================  ==========================================================
"""
from __future__ import annotations

import numpy as np
from PyQt5 import QtCore

from ..editor.playback import snap_to_frame
from .graph_gestures import (Box, HandleDrag, KeyDrag, Pan, Scale, Scrub, scaled_curves,
                             selected_curves)

__all__ = ["GraphInteraction", "PICK_PX"]

#: How near (pixels) a click must be to a key or handle to grab it.
PICK_PX = 6.0
#: A handle nearer its key than this (pixels) is under the key and not grabbed.
HANDLE_MIN_PX = 4.0
#: A press must move this far (pixels) before it is a drag rather than a click.
DRAG_PX = 3
WHEEL_ZOOM = 1.15
_OWN_KEYS = {QtCore.Qt.Key_Delete, QtCore.Qt.Key_Backspace, QtCore.Qt.Key_X, QtCore.Qt.Key_I,
             QtCore.Qt.Key_S, QtCore.Qt.Key_A, QtCore.Qt.Key_F, QtCore.Qt.Key_Home,
             QtCore.Qt.Key_Escape, QtCore.Qt.Key_Return, QtCore.Qt.Key_Enter}


class GraphInteraction(QtCore.QObject):
    """Mouse and keys of one canvas.

    Parameters
    ----------
    view : GraphView
    document : Document
    commands : module
        :mod:`rigedit.editor.graph_commands` (``CurveDrag``, ``insert_keys``,
        ``delete_keys``, ``edit_curves``).
    fps : callable
        () -> the frame rate keys snap to (the timeline's).
    set_time : callable
        Go to a time (the timeline's ``set_time``: clamped, the playback clock follows).
    status : callable
        Show a one-line message.
    """

    def __init__(self, view, document, commands, fps, set_time, status):
        super().__init__(view)
        self.view, self.document, self.commands = view, document, commands
        self.fps, self.set_time, self.status = fps, set_time, status
        self._gesture = None
        self._mouse = QtCore.QPoint(view.width() // 2, view.height() // 2)
        # moves without a button tell where the mouse is (S scales from there); no gesture,
        # no work beyond that
        view.setMouseTracking(True)
        view.installEventFilter(self)

    @property
    def busy(self):
        """Whether a gesture (drag, box, pan, scale) is in progress."""
        return self._gesture is not None

    # ================================================================== events
    def eventFilter(self, obj, event):
        if obj is not self.view:
            return False
        t = event.type()
        if t == QtCore.QEvent.ShortcutOverride and event.key() in _OWN_KEYS:
            event.accept()   # Home, Delete, ... are the canvas's while it has the focus
            return True
        handler = {QtCore.QEvent.MouseButtonPress: self._press,
                   QtCore.QEvent.MouseMove: self._move,
                   QtCore.QEvent.MouseButtonRelease: self._release,
                   QtCore.QEvent.Wheel: self._wheel,
                   QtCore.QEvent.KeyPress: self._key}.get(t)
        if handler is None:
            return False
        if t != QtCore.QEvent.KeyPress:
            self._mouse = event.pos()
        return bool(handler(event))

    def _press(self, e):
        pos, mods = e.pos(), e.modifiers()
        g = self._gesture
        if isinstance(g, Scale):
            self._end(cancel=e.button() != QtCore.Qt.LeftButton)
            return True
        if g is not None:
            return True
        if e.button() == QtCore.Qt.MiddleButton:
            self._gesture = Pan(pos)
            return True
        if e.button() != QtCore.Qt.LeftButton:
            return False
        if self.view.in_ruler(pos):
            self._gesture = Scrub()
            self._scrub(pos)
            return True
        shift = bool(mods & QtCore.Qt.ShiftModifier)
        handle = self.handle_at(pos)
        if handle is not None:
            self._gesture = HandleDrag(pos, *handle)
            return True
        key = self.key_at(pos)
        if key is None:
            self._gesture = Box(pos, shift)
            return True
        cid, k = key
        chosen = k in self.view.selected.get(cid, ())
        if shift and chosen:
            self._select({cid: [k]}, add=True, remove=True)
            return True
        if not chosen:
            self._select({cid: [k]}, add=shift)
        self._gesture = KeyDrag(pos, cid, k)
        return True

    def _move(self, e):
        g, pos = self._gesture, e.pos()
        if g is None:
            return False
        if isinstance(g, Pan):
            d = pos - g.last
            g.last = pos
            self.view.transform.pan(d.x(), d.y())
            self.view.update_view()
        elif isinstance(g, Scrub):
            self._scrub(pos)
        elif isinstance(g, Box):
            g.end = pos
            self.view.rubber_band = QtCore.QRectF(QtCore.QPointF(g.start),
                                                  QtCore.QPointF(pos)).normalized()
            self.view.update()
        elif isinstance(g, (KeyDrag, HandleDrag, Scale)):
            if not g.moved and (pos - g.start).manhattanLength() < DRAG_PX:
                return True
            g.moved = True
            free = bool(e.modifiers() & QtCore.Qt.ControlModifier)
            curves = g.curves(self, pos, free)
            if curves:
                if g.drag is None:
                    g.drag = self.commands.CurveDrag(self.document, g.label)
                g.drag.update(curves)
        return True

    def _release(self, e):
        g = self._gesture
        if g is None or isinstance(g, Scale):
            return g is not None
        if isinstance(g, Pan) and e.button() != QtCore.Qt.MiddleButton:
            return True
        if isinstance(g, Box):
            self.view.rubber_band = None
            rect = QtCore.QRectF(QtCore.QPointF(g.start), QtCore.QPointF(g.end)).normalized()
            if rect.width() < DRAG_PX and rect.height() < DRAG_PX and not g.add:
                self._select({})   # a click on nothing clears the selection
            else:
                self._select(self.keys_in(rect), add=g.add)
        self._end()
        return True

    def _wheel(self, e):
        steps = e.angleDelta().y() / 120.0
        if not steps:
            return True
        value = bool(e.modifiers() & QtCore.Qt.ControlModifier)
        pos = e.pos()
        self.view.transform.zoom(WHEEL_ZOOM ** steps, pos.x(), pos.y(), time=not value,
                                 value=value)
        self.view.update_view()
        return True

    def _key(self, e):
        k, g = e.key(), self._gesture
        if k == QtCore.Qt.Key_Escape:
            if g is not None:
                self._end(cancel=True)
            return True
        if k in (QtCore.Qt.Key_Return, QtCore.Qt.Key_Enter):
            if isinstance(g, Scale):
                self._end()
            return True
        if g is not None:
            return k in _OWN_KEYS
        actions = {QtCore.Qt.Key_Delete: self.delete_selected,
                   QtCore.Qt.Key_Backspace: self.delete_selected,
                   QtCore.Qt.Key_X: self.delete_selected,
                   QtCore.Qt.Key_I: self.insert_keys,
                   QtCore.Qt.Key_S: self.start_scale,
                   QtCore.Qt.Key_A: self.select_all,
                   QtCore.Qt.Key_F: self.view.frame_selected,
                   QtCore.Qt.Key_Home: self.view.frame_all}
        if k not in actions:
            return False
        actions[k]()
        return True

    def _end(self, cancel=False):
        """Finish (or cancel) the gesture in progress."""
        g, self._gesture = self._gesture, None
        self.view.rubber_band = None
        drag = getattr(g, "drag", None)
        if drag is not None:
            drag.cancel() if cancel else drag.finish()
        self.view.update()

    def abandon(self):
        """Drop the gesture in progress without touching the clip: something else changed
        it (an undo or redo, another rig), so the drag's picture of it is stale."""
        self._gesture = None
        self.view.rubber_band = None
        self.view.update()

    def interrupt(self):
        """The current clip is no longer the one being dragged: end the gesture (a drag of
        the old clip is put back as it was, with no undo step)."""
        if self._gesture is not None:
            self._end()

    def _scrub(self, pos):
        t = float(self.view.transform.t_of(pos.x()))
        self.set_time(snap_to_frame(max(t, 0.0), self.fps()))

    # ================================================================== hit tests
    def key_at(self, pos, radius=PICK_PX):
        """The shown key nearest to widget point ``pos`` within ``radius`` pixels:
        ``(ChannelId, index)`` or None."""
        best = None
        for c in self.view.visible_channels():
            index, xs, ys = self.view.visible_keys(c, pad=radius)
            if not len(index):
                continue
            d = np.hypot(xs - pos.x(), ys - pos.y())
            i = int(np.argmin(d))
            if d[i] <= radius and (best is None or d[i] < best[0]):
                best = (d[i], c.id, int(index[i]))
        return None if best is None else best[1:]

    def handle_at(self, pos, radius=PICK_PX):
        """The drawn handle nearest to ``pos``: ``(ChannelId, index, side, curve)`` or None
        (side ``"left"`` or ``"right"``). A handle closer than :data:`HANDLE_MIN_PX` to its
        key is not grabbed: it lies under the key (dense keys), which the click means."""
        best, tr = None, self.view.transform
        for c in self.view.visible_channels():
            sides = self.view.handle_sides(c)
            if sides is None:
                continue
            keys, handles, index, side = sides
            hx, hy = tr.x_of(handles[:, 0]), tr.y_of(handles[:, 1])
            d = np.hypot(hx - pos.x(), hy - pos.y())
            d[np.hypot(hx - tr.x_of(keys[:, 0]), hy - tr.y_of(keys[:, 1])) < HANDLE_MIN_PX] = np.inf
            i = int(np.argmin(d))
            if d[i] <= radius and (best is None or d[i] < best[0]):
                best = (d[i], c.id, int(index[i]), ("left", "right")[side[i]], c.curve)
        return None if best is None else best[1:]

    def keys_in(self, rect):
        """ChannelId -> indices of the shown keys inside widget rectangle ``rect``."""
        found = {}
        for c in self.view.visible_channels():
            index, xs, ys = self.view.visible_keys(c)
            inside = ((xs >= rect.left()) & (xs <= rect.right()) & (ys >= rect.top())
                      & (ys <= rect.bottom()))
            if inside.any():
                found[c.id] = index[inside]
        return found

    # ================================================================== selection
    def _select(self, keys, add=False, remove=False):
        sel = {k: set(v.tolist()) for k, v in self.view.selected.items()} if add else {}
        for cid, idx in keys.items():
            s = sel.setdefault(cid, set())
            (s.difference_update if remove else s.update)(int(i) for i in idx)
        self.view.set_selection({k: sorted(v) for k, v in sel.items()})

    def select_all(self):
        """Select every key of the shown channels."""
        self.view.set_selection({c.id: np.arange(len(c.curve.times))
                                 for c in self.view.visible_channels()})

    def selection(self):
        """ChannelId -> list of selected key indices, of the shown channels only."""
        shown = {c.id for c in self.view.visible_channels()}
        return {k: v.tolist() for k, v in self.view.selected.items() if k in shown and len(v)}

    # ================================================================== edits
    def delete_selected(self):
        """Delete the selected keys (one undo step)."""
        sel = self.selection()
        if not sel:
            self.status("Graph editor: no key selected to delete")
            return 0
        self.view.set_selection({})
        return self.commands.delete_keys(self.document, sel)

    def insert_keys(self):
        """A key on every shown channel at the time cursor (one undo step); on a joint with
        no keys in the clip, on each of its channels not unticked (all nine at first)."""
        view = self.view
        ids = ([c.id for c in view.visible_channels()]
               or [c.id for c in view.channels if c.id not in view.hidden])
        if not ids:
            self.status("Graph editor: no shown channel to key")
            return 0
        return self.commands.insert_keys(self.document, ids, self.document.time)

    def start_scale(self):
        """S: scale the selected keys' times about the time cursor with the mouse."""
        if not self.selection():
            self.status("Graph editor: select keys to scale")
            return
        self._gesture = Scale(self, self._mouse)
        self.status("Scale: move the mouse; click or Enter to finish, Esc to cancel")

    def scale_selected(self, time_factor, value_factor=1.0):
        """Scale the selected keys about the time cursor (time) and 0 (value): one step."""
        curves = scaled_curves(self, time_factor, value_factor)
        if not curves:
            return 0
        return self.commands.edit_curves(self.document, curves, "Scale keys")
