"""The Shapes dock: one slider per morph target of the rig, and a key button per target.

The panel never edits data itself: a slider held is an :class:`~rigedit.editor.morphs.
WeightDrag` (the mesh follows, one undo step at the release), a click on the slider's groove
or a typed number is :func:`~rigedit.editor.morphs.set_weight`, and the key button is
:func:`~rigedit.editor.morphs.key_weight` at the document's time on its current clip (the
timeline's key row then shows the key; its right-click menu deletes the key at the current
time). It follows the document's events: the weights shown
(MorphChanged: the clip sampled, an undo), the keys at the current time (KeysChanged,
TimeChanged, ClipChanged), a new rig (RigReplaced: the rows are built again).
"""
from __future__ import annotations

from PyQt5 import QtCore, QtWidgets

from ..editor import events as ev
from ..editor import morphs

__all__ = ["MorphPanel", "MorphDock", "SLIDER_STEPS"]

#: The slider runs over weights 0..1 in this many steps; the spin box takes any weight from
#: WEIGHT_RANGE (glTF does not bound weights to [0, 1]; sliders past 1 are rarely wanted).
SLIDER_STEPS = 1000
WEIGHT_RANGE = (-10.0, 10.0)
KEY_ON, KEY_OFF = "◆", "◇"   # a key at the current time, none


class _Row:
    """One target's widgets: name, slider, spin box, key button."""

    def __init__(self, panel, grid, row, name):
        self.name = name
        self.label = QtWidgets.QLabel(name)
        self.label.setToolTip(name)
        self.slider = QtWidgets.QSlider(QtCore.Qt.Horizontal)
        self.slider.setRange(0, SLIDER_STEPS)
        self.slider.setObjectName(f"shape_slider_{row}")
        self.spin = QtWidgets.QDoubleSpinBox()
        self.spin.setRange(*WEIGHT_RANGE)
        self.spin.setDecimals(3)
        self.spin.setSingleStep(0.05)
        self.spin.setKeyboardTracking(False)   # one edit per number typed, not per digit
        self.key = QtWidgets.QToolButton()
        self.key.setText(KEY_OFF)
        self.key.setToolTip(f"Key {name} at the current time on the current clip "
                            f"(right-click: delete the key there)")
        self.key.setAutoRaise(True)
        self.key.setContextMenuPolicy(QtCore.Qt.ActionsContextMenu)
        self.delete_action = QtWidgets.QAction(f"Delete {name} key", self.key)
        self.delete_action.triggered.connect(lambda: panel.delete_key(name))
        self.key.addAction(self.delete_action)
        for col, widget in enumerate((self.label, self.slider, self.spin, self.key)):
            grid.addWidget(widget, row, col)
        self.slider.sliderPressed.connect(lambda: panel.drag_started(name))
        self.slider.sliderReleased.connect(panel.drag_ended)
        self.slider.valueChanged.connect(lambda v: panel.slider_moved(name, v))
        self.spin.valueChanged.connect(lambda w: panel.set_weight(name, w))
        self.key.clicked.connect(lambda: panel.key(name))

    def show(self, weight, keyed):
        """``weight`` on the slider (clamped to its 0..1) and in the box; the key mark."""
        for widget in (self.slider, self.spin):
            widget.blockSignals(True)
        self.slider.setValue(int(round(min(max(weight, 0.0), 1.0) * SLIDER_STEPS)))
        self.spin.setValue(weight)
        for widget in (self.slider, self.spin):
            widget.blockSignals(False)
        self.key.setText(KEY_ON if keyed else KEY_OFF)
        self.delete_action.setEnabled(keyed)


class MorphPanel(QtWidgets.QWidget):
    """The sliders of the document's morph targets.

    Parameters
    ----------
    document : Document
    error : callable(message), optional
        Shows why an edit was refused (a status line); ignored when None.

    Attributes
    ----------
    rows : dict[str, _Row]
        Target name -> its widgets (``rows[name].slider``, ``.spin``, ``.key``).
    """

    def __init__(self, document, error=None, parent=None):
        super().__init__(parent)
        self.document = document
        self.error = error
        self.rows = {}
        self._drag = None
        layout = QtWidgets.QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 6)
        self.empty = QtWidgets.QLabel("This rig has no shapes (morph targets).")
        self.empty.setWordWrap(True)
        layout.addWidget(self.empty)
        self.scroll = QtWidgets.QScrollArea()
        self.scroll.setWidgetResizable(True)
        self.scroll.setFrameShape(QtWidgets.QFrame.NoFrame)
        layout.addWidget(self.scroll, 1)
        document.listen(self.on_event)
        self.rebuild()

    # ------------------------------------------------------------------ rows
    def rebuild(self):
        """One row per target of the document's rig (none: the "no shapes" line)."""
        self._drag = None
        body = QtWidgets.QWidget()
        grid = QtWidgets.QGridLayout(body)
        grid.setContentsMargins(0, 0, 0, 0)
        grid.setColumnStretch(1, 1)
        names = self.document.morph.names
        self.rows = {name: _Row(self, grid, i, name) for i, name in enumerate(names)}
        grid.setRowStretch(len(names), 1)
        self.scroll.setWidget(body)
        # up to four rows without scrolling, however the right-hand docks share the height
        row = body.sizeHint().height() / max(len(names), 1)
        self.scroll.setMinimumHeight(int(min(len(names), 4) * row))
        self.empty.setVisible(not names)
        self.scroll.setVisible(bool(names))
        self.refresh()

    def refresh(self):
        """Every row from the document: the weights shown, the keys at the current time."""
        d = self.document
        if not self.rows:
            return
        clip, weights = d.clip, d.morph.weights
        for m, (name, row) in enumerate(self.rows.items()):
            track = None if clip is None else clip.morph_tracks.get(name)
            keyed = track is not None and track.key_index(d.time, 0.5 / 30) is not None
            row.show(float(weights[m]), keyed)

    def on_event(self, event):
        if isinstance(event, ev.RigReplaced):
            self.rebuild()
        elif isinstance(event, (ev.MorphChanged, ev.ClipChanged, ev.TimeChanged)):
            self.refresh()   # KeysChanged is a ClipChanged

    # ------------------------------------------------------------------ edits
    def drag_started(self, name):
        self._drag = morphs.WeightDrag(self.document, name)

    def slider_moved(self, name, value):
        weight = value / SLIDER_STEPS
        if self._drag is not None and self._drag.target == name:
            self._drag.step(weight)
        else:   # a click on the groove, the keyboard: one step each
            self.set_weight(name, weight)

    def drag_ended(self):
        drag, self._drag = self._drag, None
        if drag is not None:
            drag.end()

    def set_weight(self, name, weight):
        self._guard(morphs.set_weight, self.document, name, weight)

    def key(self, name):
        """Key ``name``'s weight shown at the current time (one undo step)."""
        self._guard(morphs.key_weight, self.document, name)

    def delete_key(self, name):
        """Delete ``name``'s key at the current time (one undo step), if it has one."""
        self._guard(morphs.delete_weight_key, self.document, name)

    def _guard(self, edit, *args):
        try:
            edit(*args)
        except (ValueError, KeyError) as exc:
            if self.error is None:
                raise
            self.error(str(exc))


class MorphDock:
    """The Shapes dock of the window: a :class:`MorphPanel` in a QDockWidget, shown when a
    rig with shapes is opened and hidden for one without (View > Shapes shows it anyway).

    Parameters
    ----------
    parent : QMainWindow
    document : Document
    error : callable(message), optional
    """

    def __init__(self, parent, document, error=None):
        self.panel = MorphPanel(document, error)
        self.dock = QtWidgets.QDockWidget("Shapes", parent)
        self.dock.setObjectName("shapes")
        self.dock.setWidget(self.panel)
        self.dock.toggleViewAction().setStatusTip("Show the morph target sliders")
        parent.addDockWidget(QtCore.Qt.RightDockWidgetArea, self.dock)
        document.listen(self._on_event)
        self._show_for_rig(document)

    def _on_event(self, event):
        if isinstance(event, ev.RigReplaced):
            self._show_for_rig(self.panel.document)

    def _show_for_rig(self, document):
        self.dock.setVisible(bool(document.morph.names))

    def actions(self):
        """The dock's show/hide action for :func:`.menus.build_menus` (View > Shapes)."""
        return {"shapes_dock": self.dock.toggleViewAction()}
