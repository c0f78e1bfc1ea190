"""The timeline's edits as undo steps: the current clip, one Command per user action.

Key edits (:mod:`rigedit.editor.timeline_keys`) and clip edits (:mod:`rigedit.ui.timeline_clips`)
both go through :class:`ClipEdits`, which snapshots a clip (``Clip.state``, cheap because
tracks are immutable) before and after a change and pushes one
:class:`~rigedit.editor.document.Command` that restores either snapshot. Edits that changed
nothing record nothing.
"""
from __future__ import annotations

from .document import Command

__all__ = ["ClipEdits"]


class ClipEdits:
    """The document's current clip, and edits of it (or of the clip list) as undo steps.

    Parameters
    ----------
    document : Document
    on_clip_changed : callable(resample)
        Called after an edit is done, undone or redone (the timeline emits the document's
        ``"clip"`` event there); ``resample`` False says the pose need not be sampled from
        the clip again (a key written from the current pose).

    Attributes
    ----------
    own_push : bool
        True while this object pushes a step, so the auto-key can tell its own steps from
        the user's pose edits.
    stack_len : int
        The undo stack's length after the last step this object pushed or saw.
    """

    def __init__(self, document, on_clip_changed):
        self.document = document
        self.on_clip_changed = on_clip_changed
        self.own_push = False
        self.stack_len = len(document.undo_stack)

    @property
    def clip(self):
        """The current :class:`~rigedit.animation.clip.Clip`, or None."""
        name = self.document.current_clip
        return self.document.clips.get(name) if name is not None else None

    def duration(self):
        """The current clip's duration in seconds (1 without a clip or for an empty one)."""
        clip = self.clip
        return clip.duration if clip is not None and clip.duration > 0 else 1.0

    def joint_name(self):
        """The selected joint's name, or None."""
        j = self.document.selection
        return None if j is None else self.document.skeleton.names[j]

    def scope(self, all_joints):
        """The joints a key edit touches: ``[selected]``, or None for all joints."""
        name = self.joint_name()
        return None if all_joints or name is None else [name]

    def push(self, command, amend=False):
        """Push ``command`` on the document's undo stack (folded into its last step with
        ``amend``)."""
        self.own_push = True
        try:
            if amend:   # fold into the document's last step (auto-key after a pose edit)
                self.document.undo_stack.amend(command)
            else:
                self.document.push(command)
        finally:
            self.own_push = False
            self.stack_len = len(self.document.undo_stack)

    def edit_clip(self, label, change, resample=True, clip=None, amend=False):
        """Run ``change(clip)`` as one undo step (folded into the last one with ``amend``);
        nothing is recorded when it changed nothing. Returns what ``change`` returned."""
        clip = clip or self.clip
        if clip is None:
            return None
        before = clip.state()
        result = change(clip)
        after = clip.state()
        if (before[1:] == after[1:] and before[0].keys() == after[0].keys()
                and all(before[0][k] is after[0][k] for k in before[0])):
            return result
        clip.restore(before)

        def do():
            clip.restore(after)
            self.on_clip_changed(resample)

        def undo():
            clip.restore(before)
            self.on_clip_changed(True)

        self.push(Command(label, do, undo), amend=amend)
        return result

    def edit_clips(self, label, change):
        """Run ``change()`` (which edits ``document.clips`` and returns the new current
        clip's name) as one undo step."""
        d = self.document
        before = (dict(d.clips), d.current_clip)
        current = change()
        after = (dict(d.clips), current)

        def apply(state):
            clips, name = state
            d.clips.clear()
            d.clips.update(clips)
            for key, clip in clips.items():
                clip.name = key
            d.set_current_clip(name)

        apply(before)
        self.push(Command(label, lambda: apply(after), lambda: apply(before)))
