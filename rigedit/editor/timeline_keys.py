"""The timeline's key edits: the key commands (:mod:`.key_commands`) applied to the selected
joint (all joints when none is selected, or when asked) at the current time, the copy buffer,
key-mark drags, and the auto-key switch.

Every edit is one undo step. A key-mark drag (:class:`~.key_commands.KeyDrag`) moves the key
live (the clip shows it where it is dragged) and becomes one undo step at the release.
"""
from __future__ import annotations

from . import key_commands as keys

__all__ = ["KeyEditor"]


class KeyEditor:
    """Keys of the document's current clip, edited at the current time.

    Parameters
    ----------
    document : Document
    fps : callable() -> float
        The timeline's frame rate: a key within half a frame of the current time is "at" it.
    seek : callable(t)
        Moves the timeline to ``t`` seconds (a key drag starts there).
    pause : callable()
        Stops playback (a key drag pauses it).
    error : callable(message)
        Shows why an edit was refused.

    Attributes
    ----------
    auto_key : bool
        Posing writes keys at the current time (the document's ``auto_key.enabled``).
    clipboard : dict or None
        What :meth:`copy_keys` copied (``Clip.copy_keys``).
    """

    def __init__(self, document, fps, seek, pause, error):
        self.document = document
        self.fps = fps
        self.seek = seek
        self.pause = pause
        self.error = error
        self.clipboard = None
        self._drag = None

    @property
    def auto_key(self):
        return self.document.auto_key.enabled

    @auto_key.setter
    def auto_key(self, on):
        self.document.auto_key.enabled = bool(on)

    def joint_name(self):
        """The selected joint's name, or None."""
        j = self.document.selection
        return None if j is None else self.document.skeleton.names[j]

    def scope(self, all_joints):
        """The joints a key edit touches: ``[selected]``, or None for all joints."""
        name = self.joint_name()
        return None if all_joints or name is None else [name]

    def _tolerance(self):
        return 0.5 / self.fps()

    def _refusable(self, edit, *args, **kwargs):
        """Run a key edit; one it refuses (``ValueError``: a compressed clip, which is read
        only, or a mode a track cannot take) is shown with ``error`` and changes nothing."""
        try:
            return edit(*args, **kwargs)
        except ValueError as exc:
            self.error(str(exc))
            return 0

    def insert_key(self, all_joints=False, joints=None, label=None, amend=False):
        """Key the selected joint (every joint when ``all_joints`` or nothing is selected) at
        the current time from the current pose. Creates a clip when there is none."""
        joints = joints if joints is not None else self.scope(all_joints)
        return self._refusable(keys.set_key, self.document, joints, label=label, amend=amend)

    def delete_key(self, all_joints=False):
        """Delete the selected joint's (or all joints') key at the current time."""
        return self._refusable(keys.delete_key, self.document, self.scope(all_joints),
                               tolerance=self._tolerance())

    def move_key(self, old, new, all_joints=False):
        """Move the key at ``old`` seconds to ``new`` (selected joint, or all)."""
        return self._refusable(keys.move_keys, self.document, {old: new},
                               self.scope(all_joints))

    def copy_keys(self, all_joints=False):
        """Copy the selected joint's (or all) values at the current time."""
        if self.document.clip is not None:
            self.clipboard = keys.copy_keys(self.document, self.scope(all_joints))
        return self.clipboard

    def paste_keys(self):
        """Paste copied values as keys at the current time."""
        return self._refusable(keys.paste_keys, self.document, self.clipboard)

    def set_interpolation(self, mode, channel="rotation"):
        """Interpolation of the selected joint's (or all) ``rotation`` or ``vector``
        (translation and scale) tracks; a refused mode is shown, not raised."""
        return self._refusable(keys.set_interpolation, self.document, mode,
                               self.document.selection, channel)

    # ------------------------------------------------------------------ key drags
    def key_drag_start(self, t, all_joints):
        """The ruler started dragging the key mark at ``t`` (of every joint, or the
        selected one's): playback pauses and the timeline goes there."""
        self.pause()
        if self.document.clip is None:
            return
        self.seek(t)
        self._drag = self._refusable(keys.KeyDrag, self.document, t,
                                     None if all_joints else self.scope(False)) or None

    def key_drag_move(self, t):
        """The dragged key is at ``t``: the clip shows it there (not yet an undo step)."""
        if self._drag is not None:
            self._drag.move(t)

    def key_drag_end(self):
        """The drag ended: the whole move becomes one undo step."""
        drag, self._drag = self._drag, None
        if drag is not None:
            drag.end()
