"""The View menu's and the tool bar's actions: display mode, what is shown, the camera, the
pose / edit mode, the IK chain length and the drag constraint axis.

The actions show the :class:`~rigedit.ui.scene_view.SceneView`'s options; the ``set_*``
methods here change both (what scripts and tests call through the window).
"""
from __future__ import annotations

from PyQt5 import QtWidgets

from .menus import make_action

__all__ = ["ViewActions", "DISPLAY_MODES", "CAMERAS"]

#: (mode, label) of the display modes, Ctrl+1.. in this order
DISPLAY_MODES = (("solid", "Solid"), ("translucent", "Translucent + wireframe"),
                 ("wireframe", "Wireframe"))
#: (shortcut, preset) of the camera actions
CAMERAS = (("1", "front"), ("3", "side"), ("7", "top"), ("Ctrl+3", "back"))


class ViewActions:
    """The view options' actions and the mode label of the status bar.

    Parameters
    ----------
    parent : QWidget
        The actions' parent (the window: their shortcuts work anywhere in it).
    view : SceneView
    document : Document
        Its ``mode`` ("pose" or "edit").
    status : callable
        ``status(text)``.

    Attributes
    ----------
    display_actions : dict[str, QAction]
    skeleton_action, gizmos_action, weights_action, floor_action : QAction
    camera_actions : list[QAction]
    pose_mode_action, edit_mode_action : QAction
    chain_spin : QSpinBox
    axis_actions : list[QAction]
        Free, X, Y, Z.
    mode_label : QLabel
        "POSE MODE" / "EDIT MODE", for the status bar.
    """

    def __init__(self, parent, view, document, status):
        self.view = view
        self.document = document
        self.status = status
        a = self._actions = {}
        group = QtWidgets.QActionGroup(parent)
        self.display_actions = {}
        for key, (mode, label) in enumerate(DISPLAY_MODES, start=1):
            act = make_action(parent, label, lambda on, m=mode: on and self.set_display_mode(m),
                              f"Ctrl+{key}", checkable=True, checked=mode == "solid")
            group.addAction(act)
            self.display_actions[mode] = a[mode] = act
        self.skeleton_action = a["skeleton"] = make_action(
            parent, "Show skeleton", self.set_skeleton_visible, "Ctrl+B", checkable=True,
            checked=True)
        self.gizmos_action = a["gizmos"] = make_action(
            parent, "Show joint gizmos", self.set_gizmos_visible, "Ctrl+G", checkable=True,
            checked=True)
        self.weights_action = a["weights"] = make_action(
            parent, "Weight paint view", self.set_weights_view, "Ctrl+W", checkable=True,
            tip="Colour the mesh by the selected joint's influence (blue 0 → red 1)")
        self.floor_action = a["floor"] = make_action(
            parent, "Show floor", view.set_floor_visible, checkable=True, checked=True)
        self.camera_actions = []
        for key, name in CAMERAS:
            act = a[name] = make_action(parent, f"{name.capitalize()} view",
                                        lambda _=False, n=name: view.view(n), key)
            self.camera_actions.append(act)
        a["reset_camera"] = make_action(parent, "Reset camera", lambda: view.view("reset"),
                                        "Home")
        a["reset_view"] = make_action(parent, "Reset view", lambda: view.view("reset"))
        self._build_tools(parent)
        self.mode_label = QtWidgets.QLabel()

    def _build_tools(self, parent):
        a = self._actions
        group = QtWidgets.QActionGroup(parent)
        self.pose_mode_action = a["pose_mode"] = make_action(
            parent, "Pose", lambda on: on and self.set_mode("pose"), "Tab", checkable=True,
            checked=True, tip="Pose mode: drag a joint to rotate its chain")
        self.edit_mode_action = a["edit_mode"] = make_action(
            parent, "Edit (bind)", lambda on: on and self.set_mode("edit"), "Shift+Tab",
            checkable=True,
            tip="Edit mode: drag a joint to move its rest position; the skin is re-bound")
        group.addAction(self.pose_mode_action)
        group.addAction(self.edit_mode_action)
        settings = self.view.drag_settings
        self.chain_spin = a["chain_spin"] = QtWidgets.QSpinBox()
        self.chain_spin.setRange(1, 8)
        self.chain_spin.setValue(settings.chain_length)
        self.chain_spin.setToolTip("Joints above the dragged one that rotate to reach it "
                                   "(1: just aim the parent bone)")
        self.chain_spin.valueChanged.connect(
            lambda v: setattr(settings, "chain_length", int(v)))
        group = QtWidgets.QActionGroup(parent)
        self.axis_actions = []
        for k, label in enumerate(("Free", "X", "Y", "Z")):
            act = make_action(parent, label,
                              lambda on, ax=k - 1: on and self.set_axis(None if ax < 0 else ax),
                              None if k == 0 else f"Shift+{label}", checkable=True,
                              checked=k == 0, tip="Constrain drags to this axis" if k else
                              "Drag freely in the view plane")
            group.addAction(act)
            self.axis_actions.append(act)
            a[f"axis_{label.lower()}"] = act

    def actions(self):
        """name -> QAction (or the chain length's QSpinBox) for :func:`.menus.build_menus`."""
        return dict(self._actions)

    # ------------------------------------------------------------------ options
    def display_mode(self):
        return next(m for m, a in self.display_actions.items() if a.isChecked())

    def set_display_mode(self, mode):
        """"solid", "translucent" (with wireframe) or "wireframe"."""
        self.display_actions[mode].setChecked(True)
        self.view.set_display_mode(mode)

    def set_skeleton_visible(self, on):
        self.skeleton_action.setChecked(bool(on))
        self.view.set_skeleton_visible(on)

    def set_gizmos_visible(self, on):
        self.gizmos_action.setChecked(bool(on))
        self.view.set_gizmos_visible(on)

    def set_weights_view(self, on):
        """Weight paint view: colour the mesh by the selected joint's influence."""
        self.weights_action.setChecked(bool(on))
        self.view.set_weights_view(on)

    def set_axis(self, axis):
        """Constrain drags to model axis 0, 1 or 2 (X, Y, Z), or free (None)."""
        self.axis_actions[0 if axis is None else axis + 1].setChecked(True)
        self.view.set_axis(axis)

    def set_mode(self, mode):
        """"pose" (drag poses the character) or "edit" (drag moves rest positions); the view
        follows the document's ``mode`` event (:meth:`mode_changed`)."""
        if mode not in ("pose", "edit"):
            raise ValueError(f"expected mode 'pose' or 'edit', got {mode!r}")
        (self.pose_mode_action if mode == "pose" else self.edit_mode_action).setChecked(True)
        self.document.set_mode(mode)

    def mode_changed(self):
        """The document's mode changed (here or from a script): the tool bar, the view (the
        rest pose in edit mode) and the mode label follow."""
        mode = self.document.mode
        (self.pose_mode_action if mode == "pose" else self.edit_mode_action).setChecked(True)
        self.view.refresh_pose()
        self.show_mode()
        self.status("Edit mode: drag a joint to move its rest position; the skin is re-bound "
                    "on release" if mode == "edit" else "Pose mode")
        self.view.request_render()

    def show_mode(self):
        """The status bar's mode label follows the document's mode."""
        mode = self.document.mode
        self.mode_label.setText(f"  {mode.upper()} MODE  ")
        self.mode_label.setStyleSheet(
            "color: #ffd27a; font-weight: bold" if mode == "edit" else "color: #9fd0ff")

    def rig_loaded(self):
        """A rig was opened: a rig without a mesh (a BVH skeleton) has no skin to shade or
        paint."""
        has_mesh = self.view.scene.has_mesh
        for act in (self.weights_action, *self.display_actions.values()):
            act.setEnabled(has_mesh)
        if self.weights_action.isChecked() != self.view.weights_view:
            self.set_weights_view(self.view.weights_view)
        self.show_mode()
