"""Editor toggles around skinning: DQS/LBS in the view options, the weights method of
File > Recompute weights, and the per-joint "deforms" flag of the joint panel.

Installed into a :class:`~rigedit.ui.main_window.MainWindow` by :func:`install_weight_tools`
(kept apart from the window to keep it small).
"""
from __future__ import annotations

import dataclasses

from PyQt5 import QtWidgets

__all__ = ["install_weight_tools", "skeleton_with_deform", "set_joint_deform", "set_skinning"]

#: Recompute menu entries: (method, label)
RECOMPUTE_METHODS = (("heat", "Bone heat (surface)"), ("idw", "Inverse distance (idw)"))


def skeleton_with_deform(skeleton, joint, deform):
    """A copy of ``skeleton`` where ``joint`` does (True) or does not (False) take skin
    weight at the next weights computation."""
    flags = skeleton.deform.copy()
    flags[joint] = bool(deform)
    return dataclasses.replace(skeleton, deform=flags)


def set_joint_deform(document, joint, deform):
    """Set a joint's deform flag as one undo step (a rest edit: the binding is unchanged until
    the weights are recomputed). Returns False when the flag already had that value."""
    sk = document.skeleton
    if bool(sk.deform[joint]) == bool(deform):
        return False
    before = document.rest_state()
    after = (skeleton_with_deform(sk, joint, deform), before[1], before[2])
    label = f"{'Deform' if deform else 'No deform'} {sk.names[joint]}"
    document.push_rest_edit(label, before, after)
    return True


def set_skinning(window, method):
    """Skin the view with ``"lbs"`` (linear blend) or ``"dqs"`` (dual quaternions)."""
    if method not in ("lbs", "dqs"):
        raise ValueError(f"expected skinning 'lbs' or 'dqs', got {method!r}")
    window.dqs_action.setChecked(method == "dqs")  # toggled() calls back: same value, no loop
    window.scene.skinning = method
    window._refresh_pose()
    window.request_render()


def _menu(window, title):
    return next(a.menu() for a in window.menuBar().actions()
                if a.text().replace("&", "") == title)


def install_weight_tools(window):
    """Add the DQS toggle (View menu), the Recompute weights with ▸ submenu (File menu) and the
    joint panel's deform flag to ``window``."""
    # --- DQS / LBS
    dqs = QtWidgets.QAction("Dual-quaternion skinning", window)
    dqs.setCheckable(True)
    dqs.setToolTip("Skin with dual quaternions (keeps volume in twists) instead of linear "
                   "blending")
    dqs.setStatusTip(dqs.toolTip())
    window.dqs_action = dqs
    dqs.toggled.connect(lambda on: set_skinning(window, "dqs" if on else "lbs"))
    view = _menu(window, "View")
    acts = view.actions()
    view.insertAction(acts[acts.index(window.floor_action)], dqs)

    def keep_skinning(event, **_):
        if event == "rig" and window.scene.skinning != ("dqs" if dqs.isChecked() else "lbs"):
            set_skinning(window, "dqs" if dqs.isChecked() else "lbs")

    window.document.subscribe(keep_skinning)
    if dqs.isChecked():
        set_skinning(window, "dqs")

    # --- Recompute weights with a chosen method
    file_menu = _menu(window, "File")
    recompute = next(a for a in file_menu.actions()
                     if a.text().replace("&", "") == "Recompute weights")
    sub = QtWidgets.QMenu("Recompute weights with", window)
    window.recompute_actions = {}
    for method, label in RECOMPUTE_METHODS:
        act = sub.addAction(label)
        act.triggered.connect(lambda _=False, m=method: window.files.recompute_weights(m))
        window.recompute_actions[method] = act
    acts = file_menu.actions()
    after = acts[acts.index(recompute) + 1]
    file_menu.insertMenu(after, sub)
    recompute.setToolTip("Recompute the weights: bone heat for a mesh with faces, inverse "
                         "distance for a point cloud; joints flagged not deforming take none")

    def heat_available(event=None, **_):
        if event in (None, "rig"):
            window.recompute_actions["heat"].setEnabled(len(window.document.rig.faces) > 0)

    window.document.subscribe(heat_available)
    heat_available()

    # --- per-joint deform flag
    window.joint_panel.deform_toggled.connect(
        lambda j, on: set_joint_deform(window.document, j, on))
