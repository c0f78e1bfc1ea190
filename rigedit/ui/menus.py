"""The editor window's menus (File, Edit, View) and tool bar.

A mixin of :class:`~rigedit.ui.main_window.MainWindow` (split out to keep modules small); the
actions call the window's and its document's methods.
"""
from __future__ import annotations

from PyQt5 import QtCore, QtGui, QtWidgets

__all__ = ["MenusMixin"]


class MenusMixin:
    """Builds the menus and the tool bar of :class:`MainWindow`."""

    def _action(self, text, slot, shortcut=None, checkable=False, checked=False, tip=None):
        act = QtWidgets.QAction(text, self)
        if shortcut:
            act.setShortcut(QtGui.QKeySequence(shortcut))
        act.setCheckable(checkable)
        if checkable:
            act.setChecked(checked)
            act.toggled.connect(slot)
        else:
            act.triggered.connect(slot)
        if tip:
            act.setStatusTip(tip)
            act.setToolTip(tip)
        return act

    def _build_actions(self):
        f = self.files
        bar = self.menuBar()
        m = bar.addMenu("&File")
        m.addAction(self._action("&Open rig folder...", f.open_folder, "Ctrl+O"))
        m.addAction(self._action("Open mesh + skeleton...", f.open_mesh_skeleton))
        m.addAction(self._action("Open glTF or BVH file...", f.open_file, "Ctrl+Shift+O"))
        from .autorig_dialog import AutorigAction
        from .import_motion import ImportMotion

        self.autorig = AutorigAction(self)
        m.addAction(self._action("&Auto-rig mesh...", self.autorig.run, "Ctrl+Shift+A",
                                 tip="Embed a template skeleton (humanoid, quadruped or a "
                                     "skeleton file) in a mesh and open it in bind mode"))
        from .reembed import ReembedAction

        self.reembed = ReembedAction(self)
        m.addAction(self._action("Re-embed around the joints I moved", self.reembed.run,
                                 tip="After an auto-rig: pin the joints dragged in bind mode "
                                     "and place the others again around them"))

        self.motion_import = ImportMotion(self)
        m.addAction(self._action("Import motion onto this character...", self.motion_import.run,
                                 tip="Retarget a BVH, glTF or rig folder's clip onto this "
                                     "character as a new clip"))
        m.addSeparator()
        m.addAction(self._action("&Save rig", f.save, "Ctrl+S"))
        m.addAction(self._action("Save rig &as...", f.save_as, "Ctrl+Shift+S"))
        m.addSeparator()
        m.addAction(self._action("&Export glTF or BVH...", f.export, "Ctrl+E"))
        m.addAction(self._action("Export pose (JSON)...", f.export_pose))
        m.addAction(self._action("Export skeleton (JSON)...", f.export_skeleton))
        m.addSeparator()
        m.addAction(self._action("Load weights...", f.load_weights))
        m.addAction(self._action("Save weights...", f.save_weights))
        m.addAction(self._action("&Recompute weights", f.recompute_weights, "Ctrl+R"))
        m.addSeparator()
        m.addAction(self._action("Save screenshot...", f.save_screenshot))
        m.addAction(self._action("&Quit", self.close, "Ctrl+Q"))

        m = bar.addMenu("&Edit")
        self.undo_action = self._action("&Undo", self.undo, QtGui.QKeySequence.Undo)
        self.redo_action = self._action("&Redo", self.document.redo, QtGui.QKeySequence.Redo)
        m.addAction(self.undo_action)
        m.addAction(self.redo_action)
        m.addSeparator()
        m.addAction(self._action("Reset joint", self._reset_selected, "Alt+R"))
        m.addAction(self._action("Reset pose", self.document.reset_pose, "Alt+Shift+R"))
        m.addAction(self._action("Mirror pose L → R", lambda: self.document.mirror_pose("L")))
        m.addAction(self._action("Mirror pose R → L", lambda: self.document.mirror_pose("R")))

        view = bar.addMenu("&View")
        self.display_group = QtWidgets.QActionGroup(self)
        self.display_actions = {}
        for key, (mode, label) in enumerate((("solid", "Solid"),
                                             ("translucent", "Translucent + wireframe"),
                                             ("wireframe", "Wireframe")), start=1):
            act = self._action(label, lambda on, m_=mode: on and self.set_display_mode(m_),
                               f"Ctrl+{key}", checkable=True, checked=mode == "solid")
            self.display_group.addAction(act)
            self.display_actions[mode] = act
            view.addAction(act)
        view.addSeparator()
        self.skeleton_action = self._action("Show skeleton", self.set_skeleton_visible, "Ctrl+B",
                                            checkable=True, checked=True)
        self.gizmos_action = self._action("Show joint gizmos", self.set_gizmos_visible, "Ctrl+G",
                                          checkable=True, checked=True)
        self.weights_action = self._action(
            "Weight paint view", self.set_weights_view, "Ctrl+W", checkable=True,
            tip="Colour the mesh by the selected joint's influence (blue 0 → red 1)")
        self.floor_action = self._action("Show floor", self._set_floor_visible,
                                         checkable=True, checked=True)
        for a in (self.skeleton_action, self.gizmos_action, self.weights_action,
                  self.floor_action):
            view.addAction(a)
        view.addSeparator()
        self.camera_actions = []
        for key, name in (("1", "front"), ("3", "side"), ("7", "top"), ("Ctrl+3", "back")):
            act = self._action(f"{name.capitalize()} view", lambda _=False, n=name: self.view(n),
                               key)
            self.camera_actions.append(act)
            view.addAction(act)
        view.addAction(self._action("Reset camera", lambda: self.view("reset"), "Home"))

        tb = self.addToolBar("Tools")
        tb.setObjectName("tools")
        tb.setMovable(False)
        tb.setIconSize(QtCore.QSize(16, 16))
        tb.setToolButtonStyle(QtCore.Qt.ToolButtonTextOnly)
        tb.addWidget(QtWidgets.QLabel(" Mode "))
        self.mode_group = QtWidgets.QActionGroup(self)
        self.pose_mode_action = self._action("Pose", lambda on: on and self.set_mode("pose"),
                                             "Tab", checkable=True, checked=True,
                                             tip="Pose mode: drag a joint to rotate its chain")
        self.edit_mode_action = self._action(
            "Edit (bind)", lambda on: on and self.set_mode("edit"), "Shift+Tab", checkable=True,
            tip="Edit mode: drag a joint to move its rest position; the skin is re-bound")
        for a in (self.pose_mode_action, self.edit_mode_action):
            self.mode_group.addAction(a)
            tb.addAction(a)
        tb.addSeparator()
        tb.addWidget(QtWidgets.QLabel(" IK chain "))
        self.chain_spin = QtWidgets.QSpinBox()
        self.chain_spin.setRange(1, 8)
        self.chain_spin.setValue(self.chain_length)
        self.chain_spin.setToolTip("Joints above the dragged one that rotate to reach it "
                                   "(1: just aim the parent bone)")
        self.chain_spin.valueChanged.connect(lambda v: setattr(self, "chain_length", int(v)))
        tb.addWidget(self.chain_spin)
        tb.addSeparator()
        tb.addWidget(QtWidgets.QLabel(" Axis "))
        self.axis_group = QtWidgets.QActionGroup(self)
        self.axis_actions = []
        for k, label in enumerate(("Free", "X", "Y", "Z")):
            act = self._action(label, lambda on, a=k - 1: on and self.set_axis(None if a < 0 else a),
                               None if k == 0 else f"Shift+{label}", checkable=True,
                               checked=k == 0, tip="Constrain drags to this axis" if k else
                               "Drag freely in the view plane")
            self.axis_group.addAction(act)
            self.axis_actions.append(act)
            tb.addAction(act)
        tb.addSeparator()
        for mode in ("solid", "translucent", "wireframe"):
            tb.addAction(self.display_actions[mode])
        tb.addSeparator()
        tb.addAction(self.skeleton_action)
        tb.addAction(self.gizmos_action)
        tb.addAction(self.weights_action)
        tb.addSeparator()
        for act in self.camera_actions[:3]:
            tb.addAction(act)
        reset = self._action("Reset view", lambda: self.view("reset"))
        tb.addAction(reset)
        self.toolbar = tb
