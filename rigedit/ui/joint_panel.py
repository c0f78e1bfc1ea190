"""The joint panel: the hierarchy as a tree and the selected joint's local transform.

It never edits data itself: it emits what the user asked for and the main window turns that
into document commands. :meth:`JointPanel.show_joint` refreshes it from the document with
its signals blocked, so no edit loop starts.
"""
from __future__ import annotations

import numpy as np
from PyQt5 import QtCore, QtWidgets

__all__ = ["JointPanel", "InfoPanel"]

AXES = "XYZ"


def nearest_euler(angles, near):
    """Of the two XYZ Euler triples of one rotation, ``(a, b, c)`` and
    ``(a + 180, 180 - b, c + 180)`` (degrees, wrapped to [-180, 180)), the one nearest to
    ``near``, (3,) each."""
    angles = np.asarray(angles, dtype=float)
    other = (angles * [1, -1, 1] + 180.0 + 180.0) % 360.0 - 180.0

    def distance(a):
        return np.abs((a - near + 180.0) % 360.0 - 180.0).sum()

    return other if distance(other) < distance(angles) else angles


class JointPanel(QtWidgets.QWidget):
    """Tree + rotation (X/Y/Z degrees relative to rest, slider and spin box), translation,
    scale, and reset / mirror buttons.

    Signals
    -------
    joint_clicked(int)                       a joint chosen in the tree
    euler_changed(int, object)               (joint, (3,) degrees) from a spin box
    euler_dragged(int, object)               same while a slider is held (live, no undo step)
    slider_pressed(), slider_released()      bracket a slider drag (one undo step)
    translation_changed(int, object), scale_changed(int, object)
    reset_joint(int), reset_pose(), mirror(str)  "L" (left onto right) or "R"
    deform_toggled(int, bool)                the joint's "deforms" flag (takes skin weight)
    """

    joint_clicked = QtCore.pyqtSignal(int)
    euler_changed = QtCore.pyqtSignal(int, object)
    euler_dragged = QtCore.pyqtSignal(int, object)
    slider_pressed = QtCore.pyqtSignal()
    slider_released = QtCore.pyqtSignal()
    translation_changed = QtCore.pyqtSignal(int, object)
    scale_changed = QtCore.pyqtSignal(int, object)
    reset_joint = QtCore.pyqtSignal(int)
    reset_pose = QtCore.pyqtSignal()
    mirror = QtCore.pyqtSignal(str)
    deform_toggled = QtCore.pyqtSignal(int, bool)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.joint = None
        layout = QtWidgets.QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 6)
        self._build_tree(layout)
        layout.addWidget(self._rotation_group())
        layout.addWidget(self._translation_scale_group())
        layout.addLayout(self._buttons())
        self._items = []
        self._set_enabled(False)

    # ------------------------------------------------------------------ widgets
    def _build_tree(self, layout):
        """The joint tree, the selected joint's name and its "deforms" box, into ``layout``."""
        self.tree = QtWidgets.QTreeWidget()
        self.tree.setHeaderHidden(True)
        self.tree.setUniformRowHeights(True)
        self.tree.setMinimumHeight(180)
        self.tree.itemSelectionChanged.connect(self._tree_selected)
        layout.addWidget(self.tree, 3)
        self.title = QtWidgets.QLabel("No joint selected")
        self.title.setStyleSheet("font-weight: bold; padding: 2px 0;")
        layout.addWidget(self.title)
        self.deform_box = QtWidgets.QCheckBox("Deforms (takes skin weight)")
        self.deform_box.setToolTip("Off: the joint takes no weight when the weights are next "
                                   "recomputed (a root carrier, a helper joint)")
        self.deform_box.toggled.connect(
            lambda on: self.joint is not None and self.deform_toggled.emit(self.joint, on))
        layout.addWidget(self.deform_box)

    def _rotation_group(self):
        """Rotation: a slider (tenths of a degree) and a spin box per axis."""
        rot = QtWidgets.QGroupBox("Rotation (degrees from rest)")
        grid = QtWidgets.QGridLayout(rot)
        grid.setContentsMargins(6, 4, 6, 4)
        self.sliders, self.angle_boxes = [], []
        for k, axis in enumerate(AXES):
            label = QtWidgets.QLabel(axis)
            label.setStyleSheet(f"color: {['#e05555', '#4fc04f', '#5a86f0'][k]}; font-weight: bold")
            slider = QtWidgets.QSlider(QtCore.Qt.Horizontal)
            slider.setRange(-1800, 1800)  # tenths of a degree
            slider.valueChanged.connect(self._slider_moved)
            slider.sliderPressed.connect(self.slider_pressed)
            slider.sliderReleased.connect(self.slider_released)
            box = QtWidgets.QDoubleSpinBox()
            box.setRange(-180.0, 180.0)
            box.setDecimals(1)
            box.setSuffix("°")
            box.setKeyboardTracking(False)
            box.setWrapping(True)
            box.valueChanged.connect(self._angle_typed)
            grid.addWidget(label, k, 0)
            grid.addWidget(slider, k, 1)
            grid.addWidget(box, k, 2)
            self.sliders.append(slider)
            self.angle_boxes.append(box)
        return rot

    def _translation_scale_group(self):
        """Local translation (T) and scale (S): a spin box per axis each."""
        trs = QtWidgets.QGroupBox("Translation / scale (local)")
        grid = QtWidgets.QGridLayout(trs)
        grid.setContentsMargins(6, 4, 6, 4)
        self.translation_boxes, self.scale_boxes = [], []
        for k, axis in enumerate(AXES):
            grid.addWidget(QtWidgets.QLabel(axis), 0, k * 2 + 1, QtCore.Qt.AlignCenter)
            t = self._box(-1e4, 1e4, 3, self._translation_typed)
            s = self._box(0.001, 1000.0, 3, self._scale_typed)
            s.setSingleStep(0.05)
            s.setValue(1.0)
            grid.addWidget(t, 1, k * 2 + 1)
            grid.addWidget(s, 2, k * 2 + 1)
            self.translation_boxes.append(t)
            self.scale_boxes.append(s)
        grid.addWidget(QtWidgets.QLabel("T"), 1, 0)
        grid.addWidget(QtWidgets.QLabel("S"), 2, 0)
        return trs

    def _buttons(self):
        """Reset joint, reset pose, mirror left onto right and right onto left."""
        buttons = QtWidgets.QGridLayout()
        self.reset_joint_button = QtWidgets.QPushButton("Reset joint")
        self.reset_joint_button.clicked.connect(
            lambda: self.joint is not None and self.reset_joint.emit(self.joint))
        self.reset_pose_button = QtWidgets.QPushButton("Reset pose")
        self.reset_pose_button.clicked.connect(self.reset_pose)
        self.mirror_lr_button = QtWidgets.QPushButton("Mirror L → R")
        self.mirror_lr_button.clicked.connect(lambda: self.mirror.emit("L"))
        self.mirror_rl_button = QtWidgets.QPushButton("Mirror R → L")
        self.mirror_rl_button.clicked.connect(lambda: self.mirror.emit("R"))
        buttons.addWidget(self.reset_joint_button, 0, 0)
        buttons.addWidget(self.reset_pose_button, 0, 1)
        buttons.addWidget(self.mirror_lr_button, 1, 0)
        buttons.addWidget(self.mirror_rl_button, 1, 1)
        return buttons

    def _box(self, lo, hi, decimals, slot):
        box = QtWidgets.QDoubleSpinBox()
        box.setRange(lo, hi)
        box.setDecimals(decimals)
        box.setSingleStep(0.01)
        box.setKeyboardTracking(False)
        box.valueChanged.connect(slot)
        return box

    def _set_enabled(self, on):
        for w in (self.sliders + self.angle_boxes + self.translation_boxes + self.scale_boxes
                  + [self.reset_joint_button, self.deform_box]):
            w.setEnabled(on)

    # ------------------------------------------------------------------ from the document
    def set_skeleton(self, skeleton):
        """Rebuild the tree."""
        self.tree.blockSignals(True)
        self.tree.clear()
        self._items = []
        for j, name in enumerate(skeleton.names):
            p = skeleton.parents[j]
            item = QtWidgets.QTreeWidgetItem([name])
            item.setData(0, QtCore.Qt.UserRole, j)
            if p < 0:
                self.tree.addTopLevelItem(item)
            else:
                self._items[p].addChild(item)
            self._items.append(item)
        self.tree.expandAll()
        self.tree.blockSignals(False)
        self.joint = None
        self.show_joint(None, None)

    def show_joint(self, joint, pose):
        """Show ``joint``'s values from ``pose`` (signals blocked). For the joint already
        shown, the angles stay the Euler triple nearest to those on display (a slider held
        past 90 degrees on Y must not jump to the other triple of the same rotation)."""
        same_joint = joint is not None and joint == self.joint
        self.joint = joint
        widgets = (self.sliders + self.angle_boxes + self.translation_boxes + self.scale_boxes
                   + [self.tree, self.deform_box])
        for w in widgets:
            w.blockSignals(True)
        try:
            if joint is None:
                self.tree.clearSelection()
                self.title.setText("No joint selected (click a sphere or a name)")
                self._set_enabled(False)
                return
            self._set_enabled(True)
            item = self._items[joint]
            if not item.isSelected():
                self.tree.clearSelection()
                item.setSelected(True)
                self.tree.scrollToItem(item)
            self.title.setText(f"Joint: {pose.skeleton.names[joint]}")
            self.deform_box.setChecked(bool(pose.skeleton.deform[joint]))
            angles = pose.get_euler(joint, degrees=True)
            if same_joint:
                angles = nearest_euler(angles, self.angles())
            for k in range(3):
                self.angle_boxes[k].setValue(float(angles[k]))
                self.sliders[k].setValue(int(round(angles[k] * 10)))
                self.translation_boxes[k].setValue(float(pose.translation[joint, k]))
                self.scale_boxes[k].setValue(float(pose.scale[joint, k]))
        finally:
            for w in widgets:
                w.blockSignals(False)

    # ------------------------------------------------------------------ from the user
    def _tree_selected(self):
        items = self.tree.selectedItems()
        if items:
            self.joint_clicked.emit(int(items[0].data(0, QtCore.Qt.UserRole)))

    def angles(self):
        return np.array([b.value() for b in self.angle_boxes])

    def _angle_typed(self, _value):
        if self.joint is not None:
            self.euler_changed.emit(self.joint, self.angles())

    def _slider_moved(self, _value):
        if self.joint is None:
            return
        angles = np.array([s.value() / 10.0 for s in self.sliders])
        for box, a in zip(self.angle_boxes, angles):
            box.blockSignals(True)
            box.setValue(float(a))
            box.blockSignals(False)
        if any(s.isSliderDown() for s in self.sliders):
            self.euler_dragged.emit(self.joint, angles)
        else:  # keyboard or page step on the slider: a complete edit
            self.euler_changed.emit(self.joint, angles)

    def _translation_typed(self, _value):
        if self.joint is not None:
            self.translation_changed.emit(self.joint, np.array([b.value() for b in self.translation_boxes]))

    def _scale_typed(self, _value):
        if self.joint is not None:
            self.scale_changed.emit(self.joint, np.array([b.value() for b in self.scale_boxes]))


class InfoPanel(QtWidgets.QWidget):
    """Counts of the rig: vertices, faces, joints, bones, clips; and the selected joint."""

    FIELDS = ("Rig", "Vertices", "Faces", "Joints", "Bones", "Clips", "Selected", "Influences",
              "Vertex")

    def __init__(self, parent=None):
        super().__init__(parent)
        form = QtWidgets.QFormLayout(self)
        form.setContentsMargins(8, 6, 8, 6)
        form.setLabelAlignment(QtCore.Qt.AlignRight)
        self.labels = {}
        for f in self.FIELDS:
            lab = QtWidgets.QLabel("-")
            lab.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
            form.addRow(f + ":", lab)
            self.labels[f] = lab

    def show_rig(self, rig):
        self.labels["Rig"].setText(rig.name)
        self.labels["Vertices"].setText(f"{len(rig.vertices):,}")
        self.labels["Faces"].setText(f"{len(rig.faces):,}")
        self.labels["Joints"].setText(str(len(rig.skeleton)))
        self.labels["Bones"].setText(str(rig.num_bones))
        self.labels["Clips"].setText(str(len(rig.clips)))
        self.labels["Influences"].setText(f"{rig.binding.indices.shape[1]} per vertex"
                                          if len(rig.vertices) else "- (no mesh)")

    def show_selection(self, rig, joint):
        if joint is None:
            self.labels["Selected"].setText("-")
            return
        count = int((rig.weights[:, joint] > 1e-3).sum())
        self.labels["Selected"].setText(f"{rig.skeleton.names[joint]} ({count:,} vertices)")

    def show_vertex(self, vertex, influences):
        """A clicked vertex and its influences, ``[(joint name, weight), ...]`` largest first;
        ``vertex`` None clears it."""
        lab = self.labels["Vertex"]
        if vertex is None:
            lab.setText("-")
            return
        lines = [f"#{vertex:,}"] + [f"{name}: {w:.3f}" for name, w in influences]
        lab.setText("\n".join(lines))
