"""Editor toggles around skinning: DQS/LBS in the view options, the weights method of
File > Recompute weights, and the per-joint "deforms" flag of the joint panel."""
from __future__ import annotations

from PyQt5 import QtWidgets

from ..editor import events as ev
# the flag's edit is the editor's (no Qt); kept importable from here
from ..editor.deform import set_joint_deform, skeleton_with_deform

__all__ = ["WeightTools", "skeleton_with_deform", "set_joint_deform"]

#: Recompute menu entries: (method, label)
RECOMPUTE_METHODS = (("heat", "Bone heat (surface)"), ("idw", "Inverse distance (idw)"))


class WeightTools:
    """View > Dual-quaternion skinning, File > Recompute weights with ▸ and the joint panel's
    deform flag.

    Parameters
    ----------
    parent : QWidget
        The actions' parent.
    document : Document
    view : SceneView
        Skins with LBS or DQS.
    recompute_weights : callable
        ``recompute_weights(method)`` (:meth:`FileActions.recompute_weights
        <rigedit.ui.file_actions.FileActions.recompute_weights>`).
    joint_panel : JointPanel
        Its ``deform_toggled(joint, on)`` sets the flag.

    Attributes
    ----------
    dqs_action : QAction
    recompute_menu : QMenu
    recompute_actions : dict[str, QAction]
        method -> its entry in the submenu.
    """

    def __init__(self, parent, document, view, recompute_weights, joint_panel):
        self.document = document
        self.view = view
        dqs = self.dqs_action = QtWidgets.QAction("Dual-quaternion skinning", parent)
        dqs.setCheckable(True)
        dqs.setToolTip("Skin with dual quaternions (keeps volume in twists) instead of linear "
                       "blending")
        dqs.setStatusTip(dqs.toolTip())
        dqs.toggled.connect(lambda on: self.set_skinning("dqs" if on else "lbs"))
        self.recompute_menu = QtWidgets.QMenu("Recompute weights with", parent)
        self.recompute_actions = {}
        for method, label in RECOMPUTE_METHODS:
            act = self.recompute_menu.addAction(label)
            act.triggered.connect(lambda _=False, m=method: recompute_weights(m))
            self.recompute_actions[method] = act
        joint_panel.deform_toggled.connect(lambda j, on: set_joint_deform(document, j, on))
        document.listen(self._on_event)
        self._on_event(ev.RigReplaced())

    def actions(self):
        """name -> QAction or QMenu for :func:`.menus.build_menus`."""
        return {"dqs": self.dqs_action, "recompute_with": self.recompute_menu}

    def _on_event(self, event):
        if not isinstance(event, ev.RigReplaced):
            return
        method = "dqs" if self.dqs_action.isChecked() else "lbs"
        if self.view.scene.skinning != method:   # a new scene keeps the chosen skinning
            self.set_skinning(method)
        self.recompute_actions["heat"].setEnabled(len(self.document.rig.faces) > 0)

    def set_skinning(self, method):
        """Skin the view with ``"lbs"`` (linear blend) or ``"dqs"`` (dual quaternions)."""
        if method not in ("lbs", "dqs"):
            raise ValueError(f"expected skinning 'lbs' or 'dqs', got {method!r}")
        self.dqs_action.setChecked(method == "dqs")  # toggled() calls back: same value, no loop
        self.view.set_skinning(method)
