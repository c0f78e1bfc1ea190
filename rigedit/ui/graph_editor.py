"""The graph editor dock (View > Graph editor, under the timeline): the selected joint's
animation channels as curves, with a tool row and a channel list.

The dock wires three parts: :class:`~.graph_channels.ChannelList` (which channels are shown),
:class:`~.graph_view.GraphView` (the canvas) and :class:`~.graph_interaction.GraphInteraction`
(mouse and keys -> :mod:`rigedit.editor.graph_commands`). It follows the document's events:
the channels are read again on KeysChanged / ClipChanged / SelectionChanged / RigReplaced
(each edit, its undo and the timeline's own key edits), the cursor moves on TimeChanged. While
the dock is hidden it reads nothing and catches up when shown.
"""
from __future__ import annotations

from PyQt5 import QtCore, QtWidgets

from ..editor import events as ev
from ..editor import graph_commands
from .graph_channels import ChannelList
from .graph_interaction import GraphInteraction
from .graph_view import GraphView

__all__ = ["GraphEditor"]

INTERPOLATIONS = (("constant", "Constant"), ("linear", "Linear"), ("bezier", "Bezier"))
HANDLE_TYPES = (("auto_clamped", "Auto clamped"), ("auto", "Auto"), ("aligned", "Aligned"),
                ("free", "Free"), ("vector", "Vector"))
EASINGS = (("ease_in", "Ease in"), ("ease_out", "Ease out"), ("ease_in_out", "Ease in-out"))
NO_JOINT = "Select a joint to see its animation curves"
NO_CLIP = "No clip: add one in the timeline"
NO_TRACK = "{joint} has no keys in this clip: I keys the shown channels at the cursor"


def _button(text, tip, slot):
    b = QtWidgets.QToolButton()
    b.setText(text)
    b.setToolTip(tip)
    b.clicked.connect(slot)
    return b


class GraphEditor:
    """The graph editor of the window.

    Parameters
    ----------
    parent : QMainWindow
        The window; the dock goes under its ``timeline`` dock, hidden until View > Graph
        editor shows it.
    document : Document
    timeline : TimelineDock
        Its frame rate (``fps``) and ``set_time`` (the time cursor is shared).
    status : callable
        ``status(text)``: the status line.

    Attributes
    ----------
    dock : QDockWidget
    view : GraphView
    channel_list : ChannelList
    interaction : GraphInteraction
    """

    def __init__(self, parent, document, timeline, status):
        self.document, self.status = document, status
        self.view = GraphView(lambda: timeline.fps)
        self.view.selection_changed.connect(self._show_handle_type)
        self.channel_list = ChannelList()
        self.channel_list.visibility_changed.connect(self._on_visibility)
        self.interaction = GraphInteraction(self.view, document, graph_commands,
                                            lambda: timeline.fps, timeline.set_time, status)
        self.dock = QtWidgets.QDockWidget("Graph editor", parent)
        self.dock.setObjectName("graph_editor")
        self.dock.setWidget(self._body())
        action = self.dock.toggleViewAction()
        action.setText("Graph editor")
        action.setStatusTip("Show the selected joint's animation curves")
        parent.addDockWidget(QtCore.Qt.BottomDockWidgetArea, self.dock)
        parent.splitDockWidget(timeline, self.dock, QtCore.Qt.Vertical)
        self.dock.hide()
        self.dock.visibilityChanged.connect(lambda shown: shown and self._catch_up())
        # the frame numbers on the graph's ruler are the timeline's frames
        timeline.fps_spin.valueChanged.connect(lambda _fps: self.view.update_view())
        # what is shown: (rig, clip, joint); when it changes the key selection is dropped
        # and the view framed again
        self._shown = None
        self._stale = True
        document.listen(self._on_event)

    def actions(self):
        """The dock's show/hide action for :func:`.menus.build_menus` (View > Graph editor)."""
        return {"graph_dock": self.dock.toggleViewAction()}

    # ================================================================== widgets
    def _body(self):
        body = QtWidgets.QWidget()
        lay = QtWidgets.QVBoxLayout(body)
        lay.setContentsMargins(4, 2, 4, 2)
        lay.setSpacing(2)
        lay.addLayout(self._tool_row())
        split = QtWidgets.QSplitter(QtCore.Qt.Horizontal)
        split.addWidget(self.channel_list)
        split.addWidget(self.view)
        split.setStretchFactor(1, 1)
        split.setSizes([170, 900])
        lay.addWidget(split, 1)
        return body

    def _tool_row(self):
        row = QtWidgets.QHBoxLayout()
        self.joint_label = QtWidgets.QLabel("no joint")
        self.joint_label.setToolTip("The joint whose channels are shown (select another in "
                                    "the 3D view or the joint list)")
        font = self.joint_label.font()
        font.setBold(True)
        self.joint_label.setFont(font)
        row.addWidget(self.joint_label)
        row.addSpacing(10)
        row.addWidget(QtWidgets.QLabel("Interpolation"))
        for name, text in INTERPOLATIONS:
            row.addWidget(_button(text, f"{text} from the selected keys to the next",
                                  lambda _=False, n=name: self.set_interpolation(n)))
        self.handle_combo = QtWidgets.QComboBox()
        for name, text in HANDLE_TYPES:
            self.handle_combo.addItem(text, name)
        self.handle_combo.setToolTip("Handle type of the selected keys (auto clamped: no "
                                     "overshoot; aligned / free: drag the handles)")
        self.handle_combo.activated.connect(
            lambda i: self.set_handle_type(self.handle_combo.itemData(i)))
        row.addWidget(QtWidgets.QLabel("  Handles"))
        row.addWidget(self.handle_combo)
        row.addWidget(QtWidgets.QLabel("  Easing"))
        for name, text in EASINGS:
            row.addWidget(_button(text, f"{text} on the selected keys",
                                  lambda _=False, n=name: self.set_easing(n)))
        row.addSpacing(12)
        i = self.interaction
        for text, tip, slot in (
                ("Scale", "Scale the selected keys' times about the time cursor (S)",
                 self._ask_scale),
                ("Frame all", "Show every key (Home)", self.view.frame_all),
                ("Frame selected", "Show the selected keys (F)", self.view.frame_selected),
                ("Insert key", "A key on every shown channel at the time cursor (I)",
                 i.insert_keys),
                ("Delete", "Delete the selected keys (Delete)", i.delete_selected)):
            row.addWidget(_button(text, tip, slot))
        row.addStretch(1)
        return row

    # ================================================================== tool row edits
    def _per_key(self, command, name, what):
        sel = self.interaction.selection()
        if not sel:
            self.status(f"Graph editor: select keys to set {what}")
            return 0
        return command(self.document, sel, name)

    def set_interpolation(self, name):
        """Interpolation ``name`` from the selected keys to the next (one undo step)."""
        return self._per_key(graph_commands.set_interpolation, name, "their interpolation")

    def set_handle_type(self, name):
        """Handle type ``name`` on the selected keys (one undo step)."""
        return self._per_key(graph_commands.set_handle_type, name, "their handle type")

    def set_easing(self, name):
        """Easing preset ``name`` on the selected keys (one undo step)."""
        return self._per_key(graph_commands.set_easing, name, "an easing")

    def _show_handle_type(self):
        """The Handles box shows the first selected key's out-handle type."""
        view = self.view
        for c in view.visible_channels():
            idx = view.selected.get(c.id)
            if idx is not None and len(idx):
                row = self.handle_combo.findData(str(c.curve.right_type[idx[0]]))
                if row >= 0:
                    self.handle_combo.setCurrentIndex(row)   # activated is not emitted
                return

    def _ask_scale(self):
        if not self.interaction.selection():
            self.status("Graph editor: select keys to scale")
            return
        factor, ok = QtWidgets.QInputDialog.getDouble(
            self.dock, "Scale keys", "Time factor about the time cursor:", 1.0, 0.01, 100.0, 3)
        if ok:
            self.interaction.scale_selected(factor)

    # ================================================================== document events
    def _on_event(self, event):
        i = self.interaction
        if i.busy:
            # a drag's step is recorded after its gesture ends: an undo step or a new rig
            # meanwhile came from elsewhere (Ctrl+Z during a drag)
            if isinstance(event, (ev.UndoChanged, ev.RigReplaced)):
                i.abandon()
            elif type(event) is ev.ClipChanged:   # another clip chosen (not KeysChanged)
                i.interrupt()
        if isinstance(event, ev.TimeChanged):
            self.view.set_time(event.time)
        elif isinstance(event, (ev.ClipChanged, ev.SelectionChanged, ev.RigReplaced)):
            self._stale = True   # KeysChanged is a ClipChanged
            if self.dock.isVisible():
                self._catch_up()

    def _catch_up(self):
        """Read the channels again (after an edit, another joint or clip, a new rig)."""
        if not self._stale:
            return
        self._stale = False
        d, view = self.document, self.view
        joint = d.selection
        name = None if joint is None else d.skeleton.names[joint]
        chans = [] if joint is None else graph_commands.channels(d, [joint])
        shown = (id(d.rig), d.current_clip, name)
        if shown != self._shown:
            view.selected = {}
        self.channel_list.set_channels(chans)
        view.hidden = self.channel_list.hidden
        clip = d.clip
        view.duration = clip.duration if clip is not None and clip.duration > 0 else 1.0
        view.time = d.time
        view.message = (NO_CLIP if clip is None else NO_JOINT if joint is None
                        else NO_TRACK.format(joint=name))
        view.set_channels(chans)
        # (not in the dock's title: that is the View menu's text too)
        self.joint_label.setText("no joint" if name is None else name)
        if shown != self._shown:
            self._shown = shown
            view.frame_all()

    def _on_visibility(self):
        self.view.hidden = self.channel_list.hidden
        self.view.update_view()
