"""The graph editor's gestures: what a press started (a pan, a scrub, a box, a key or handle
drag, an S scale) and, for the edits, the curves the mouse's place makes of the curves as they
were when the gesture began. :class:`~.graph_interaction.GraphInteraction` holds one at a time
and hands the curves to its ``CurveDrag``.
"""
from __future__ import annotations

import numpy as np

from ..editor.graph_commands import moved_keys
from ..editor.playback import snap_to_frame

__all__ = ["Pan", "Scrub", "Box", "KeyDrag", "HandleDrag", "Scale", "selected_curves",
           "scaled_curves"]


def selected_curves(interaction):
    """ChannelId -> (curve, selected indices) of the shown channels with selected keys."""
    view = interaction.view
    return {c.id: (c.curve, view.selected[c.id]) for c in view.visible_channels()
            if len(view.selected.get(c.id, ()))}


def scaled_curves(interaction, time_factor, value_factor, base=None):
    """ChannelId -> the selected keys' curve scaled about the time cursor (time) and 0
    (value); ``base``: :func:`selected_curves` (read now when None)."""
    base = selected_curves(interaction) if base is None else base
    pivot = interaction.document.time
    return {cid: cv.scaled(idx, pivot, time_factor, 0.0, value_factor)
            for cid, (cv, idx) in base.items()}


class Pan:
    """Middle-drag: the view follows the mouse."""

    def __init__(self, pos):
        self.last = pos


class Scrub:
    """A press on the ruler: the time cursor follows the mouse."""


class Box:
    """Box selection from ``start`` to ``end`` (``add``: Shift held)."""

    def __init__(self, pos, add):
        self.start = self.end = pos
        self.add = add


class KeyDrag:
    """The selected keys follow the mouse; the grabbed key's time lands on a frame."""

    label = "Move keys"

    def __init__(self, pos, cid, index):
        self.start, self.cid, self.index = pos, cid, index
        self.moved, self.drag, self.base = False, None, None

    def curves(self, interaction, pos, free):
        if self.base is None:   # the curves as they were when the drag began
            self.base = selected_curves(interaction)
        tr = interaction.view.transform
        grabbed = self.base[self.cid][0]
        t_key = float(grabbed.times[self.index])
        t_new = t_key + float(tr.t_of(pos.x()) - tr.t_of(self.start.x()))
        if not free:
            t_new = snap_to_frame(t_new, interaction.fps())
        dt = t_new - t_key
        dv = float(tr.v_of(pos.y()) - tr.v_of(self.start.y()))
        # one time offset for every channel, clamped to all of them: keys of one time stay
        # one key in the timeline when one channel has a neighbour in the way
        return moved_keys(self.base, dt, dv)


class HandleDrag:
    label = "Move handle"

    def __init__(self, pos, cid, index, side, curve):
        self.start, self.cid, self.index, self.side, self.base = pos, cid, index, side, curve
        self.moved, self.drag = False, None
        h = curve.left[index] if side == "left" else curve.right[index]
        self.grab = np.asarray(h, dtype=float).copy()

    def curves(self, interaction, pos, free):
        tr = interaction.view.transform
        point = (self.grab[0] + float(tr.t_of(pos.x()) - tr.t_of(self.start.x())),
                 self.grab[1] + float(tr.v_of(pos.y()) - tr.v_of(self.start.y())))
        return {self.cid: self.base.with_handle(self.index, self.side, point)}


class Scale:
    """The time factor is the mouse's distance from the cursor over its distance at S (or,
    when S was pressed near the cursor, 1 + the mouse's travel over 200 pixels)."""

    label = "Scale keys"

    def __init__(self, interaction, pos):
        self.start, self.moved, self.drag = pos, True, None
        self.base = selected_curves(interaction)
        self.x_pivot = float(interaction.view.transform.x_of(interaction.document.time))

    def curves(self, interaction, pos, free):
        reach = self.start.x() - self.x_pivot
        factor = ((pos.x() - self.x_pivot) / reach if abs(reach) >= 20
                  else 1.0 + (pos.x() - self.start.x()) / 200.0)
        if not free:
            factor = round(factor * 20) / 20   # steps of 0.05; Ctrl: free
        if abs(factor) < 0.05:                 # keys do not collapse onto one time
            factor = 0.05 if factor >= 0 else -0.05
        interaction.status(f"Scale: x{factor:.2f} about {interaction.document.time:.3f} s")
        return scaled_curves(interaction, factor, 1.0, self.base)
