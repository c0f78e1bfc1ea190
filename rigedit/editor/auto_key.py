"""The auto-key: while it is on, a pose edit writes keys at the current time.

It watches the history (an observer of the undo stack, called before the document announces
the change, so listeners hear of the step with its keys already in it): a new step pushed that is a pose
edit (not a clip edit, not an undo or redo) in pose mode, with a current clip and no drag held,
keys the joints whose pose now differs from the clip, folded into that same step, as the user
made one edit. A morph weight edit (:mod:`.morphs`) keys the targets whose weight differs.
"""
from __future__ import annotations

from .clip_edits import ClipCommand
from .key_commands import changed_joints, set_key
from .morphs import MorphCommand, changed_targets, key_weight

__all__ = ["AutoKey"]


class AutoKey:
    """The document's auto-key (built by the :class:`~rigedit.editor.document.Document`).

    Parameters
    ----------
    document : Document

    Attributes
    ----------
    enabled : bool
        Off by default; the timeline's Auto-key box sets it.
    """

    def __init__(self, document):
        self.document = document
        self.enabled = False
        document.undo_stack.observers.insert(0, self.history_changed)

    def history_changed(self):
        """Key what a new pose edit moved, when on. Returns the joints keyed (names)."""
        d, stack = self.document, self.document.undo_stack
        if (not self.enabled or stack.last_action != "push" or isinstance(stack.top, ClipCommand)
                or d.clip is None or d.mode != "pose" or d.dragging):
            return []
        if isinstance(stack.top, MorphCommand):
            targets = changed_targets(d)
            for target in targets:
                key_weight(d, target, amend=True)
            return targets
        joints = changed_joints(d)
        if joints:
            set_key(d, joints=joints, amend=True, label=f"auto-key {', '.join(joints)}")
        return joints
