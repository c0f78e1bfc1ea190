"""The Edit menu: undo and redo (named after the step they would undo or redo), reset and
mirror of the pose."""
from __future__ import annotations

from PyQt5 import QtGui

from .menus import make_action

__all__ = ["EditActions"]


class EditActions:
    """Undo, redo, reset and mirror actions.

    Parameters
    ----------
    parent : QWidget
        The actions' parent.
    document : Document
    rebind : RestRebind
        Undo cancels its running re-bind when that is the latest edit.

    Attributes
    ----------
    undo_action, redo_action : QAction
    """

    def __init__(self, parent, document, rebind):
        self.document = document
        self.rebind = rebind
        d = document
        self.undo_action = make_action(parent, "&Undo", self.undo, QtGui.QKeySequence.Undo)
        self.redo_action = make_action(parent, "&Redo", d.redo, QtGui.QKeySequence.Redo)
        self._actions = {
            "undo": self.undo_action, "redo": self.redo_action,
            "reset_joint": make_action(parent, "Reset joint", self.reset_selected, "Alt+R"),
            "reset_pose": make_action(parent, "Reset pose", d.reset_pose, "Alt+Shift+R"),
            "mirror_l_to_r": make_action(parent, "Mirror pose L → R",
                                         lambda: d.mirror_pose("L")),
            "mirror_r_to_l": make_action(parent, "Mirror pose R → L",
                                         lambda: d.mirror_pose("R")),
        }

    def actions(self):
        """name -> QAction for :func:`.menus.build_menus`."""
        return dict(self._actions)

    def undo(self):
        """Edit > Undo: cancels a running re-bind when it is the latest edit, else undoes the
        document's last step."""
        return self.rebind.undo()

    def reset_selected(self):
        if self.document.selection is not None:
            self.document.reset_joint(self.document.selection)

    def update(self):
        """Undo and Redo say what they would do, and are enabled only when they can."""
        s = self.document.undo_stack
        pending = self.rebind.undoable()
        if pending is not None:
            self.undo_action.setEnabled(True)  # undo cancels the running re-bind
            self.undo_action.setText(f"&Undo {pending[2]}")
        else:
            self.undo_action.setEnabled(s.can_undo)
            self.undo_action.setText(f"&Undo {s.undo_label}".strip())
        self.redo_action.setEnabled(s.can_redo)
        self.redo_action.setText(f"&Redo {s.redo_label}".strip())
