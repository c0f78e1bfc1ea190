"""The weight brush's settings row (see :mod:`rigedit.ui.weight_brush`)."""
from __future__ import annotations

from PyQt5 import QtCore, QtWidgets

from ..editor.weight_stroke import MODES

__all__ = ["BrushPanel"]


class BrushPanel(QtWidgets.QWidget):
    """The brush's settings in one row (a tool bar shown while the brush is on): mode, radius
    (pixels), strength, value of ``set``, X-mirror and the lock of the selected joint. Read by
    :class:`WeightBrush` at each dab.

    Signals
    -------
    lock_toggled(bool)   the user locked or unlocked the selected joint
    """

    lock_toggled = QtCore.pyqtSignal(bool)

    def __init__(self, parent=None):
        super().__init__(parent)
        row = QtWidgets.QHBoxLayout(self)
        row.setContentsMargins(4, 0, 4, 0)

        def add(label, widget):
            if label:
                row.addWidget(QtWidgets.QLabel(label))
            row.addWidget(widget)

        self.mode_box = QtWidgets.QComboBox()
        for m in MODES:
            self.mode_box.addItem(m.capitalize(), m)
        add(" Brush ", self.mode_box)
        self.radius_box = QtWidgets.QSpinBox()
        self.radius_box.setRange(2, 500)
        self.radius_box.setValue(40)
        self.radius_box.setSuffix(" px")
        self.radius_box.setToolTip("Brush radius on screen; it paints the vertices within that "
                                   "distance of the surface point under the mouse")
        add(" Radius ", self.radius_box)
        self.strength_box = self._unit_box(0.2, "How much one dab changes a weight at the "
                                                "brush centre (0-1); a stroke adds up dabs")
        add(" Strength ", self.strength_box)
        self.value_box = self._unit_box(1.0, "The weight Set paints towards")
        add(" Set value ", self.value_box)
        self.mirror_box = QtWidgets.QCheckBox("X-mirror")
        self.mirror_box.setToolTip("Paint the mirror joint on the other side too")
        add(None, self.mirror_box)
        self.lock_box = QtWidgets.QCheckBox("Lock selected joint")
        self.lock_box.setToolTip("A locked joint's weights do not change while other joints "
                                 "are painted")
        self.lock_box.toggled.connect(self.lock_toggled)
        add(None, self.lock_box)
        self.locked_label = QtWidgets.QLabel("Locked: none")
        add(None, self.locked_label)
        hint = QtWidgets.QLabel("  Paints the selected joint; Ctrl+click: a vertex's influences")
        hint.setStyleSheet("color: #999")
        add(None, hint)
        row.addStretch(1)

    @staticmethod
    def _unit_box(value, tip):
        box = QtWidgets.QDoubleSpinBox()
        box.setRange(0.0, 1.0)
        box.setDecimals(2)
        box.setSingleStep(0.05)
        box.setValue(value)
        box.setToolTip(tip)
        return box

    @property
    def mode(self):
        return self.mode_box.currentData()

    def set_mode(self, mode):
        self.mode_box.setCurrentIndex(MODES.index(mode))

    def show_lock(self, joint_locked, names):
        """Reflect the selected joint's lock (signals blocked) and list the locked joints."""
        self.lock_box.blockSignals(True)
        self.lock_box.setChecked(bool(joint_locked))
        self.lock_box.blockSignals(False)
        self.locked_label.setText("Locked: " + (", ".join(names) if names else "none"))
