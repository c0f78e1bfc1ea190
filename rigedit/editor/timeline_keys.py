"""The timeline's key edits: insert, delete, move (also by dragging a key mark), copy and
paste keys, set interpolation, and the auto-key.

Every edit is one undo step through :class:`~rigedit.editor.timeline_edits.ClipEdits`. The
auto-key watches the undo stack: a new pose edit that was not the timeline's own (and not
an undo) while auto-key is on keys the joints it moved, folded into the same undo step.
"""
from __future__ import annotations

import numpy as np

__all__ = ["KeyEditor"]


class KeyEditor:
    """Keys of the document's current clip, edited at the current time.

    Parameters
    ----------
    document : Document
    edits : ClipEdits
        The current clip, the selected joint and the undo steps.
    fps : callable() -> float
        The timeline's frame rate: a key within half a frame of the current time is "at" it.
    seek : callable(t)
        Moves the timeline to ``t`` seconds (a key drag starts there).
    pause : callable()
        Stops playback (a key drag pauses it).
    show_time : callable(t)
        Shows the clip at ``t`` while a key is dragged (the key already moved).
    new_clip : callable()
        Adds an empty clip (a key inserted with no clip makes one).
    error : callable(message)
        Shows why an edit was refused.

    Attributes
    ----------
    auto_key : bool
        Posing writes keys at the current time.
    clipboard : dict or None
        What :meth:`copy_keys` copied (``Clip.copy_keys``).
    """

    def __init__(self, document, edits, fps, seek, pause, show_time, new_clip, error):
        self.document = document
        self.edits = edits
        self.fps = fps
        self.seek = seek
        self.pause = pause
        self.show_time = show_time
        self.new_clip = new_clip
        self.error = error
        self.auto_key = False
        self.clipboard = None
        self._drag = None

    def insert_key(self, all_joints=False, joints=None, label=None, amend=False):
        """Key the selected joint (every joint when ``all_joints`` or nothing is selected) at
        the current time from the current pose. Creates a clip when there is none."""
        if self.edits.clip is None:
            self.new_clip()
        joints = joints if joints is not None else self.edits.scope(all_joints)
        t = self.document.time
        what = "all joints" if joints is None else ", ".join(joints)
        return self.edits.edit_clip(label or f"Key {what} at {t:.2f}s",
                                    lambda c: c.key_pose(self.document.pose, t, joints),
                                    resample=False, amend=amend)

    def _near_key(self, joints, t=None):
        """The key time within half a frame of ``t`` (the current time), or None."""
        clip = self.edits.clip
        if clip is None:
            return None
        t = self.document.time if t is None else t
        times = clip.key_times() if joints is None else np.unique(np.concatenate(
            [clip.key_times(j) for j in joints]))
        if len(times) == 0:
            return None
        k = times[np.argmin(np.abs(times - t))]
        return float(k) if abs(k - t) <= 0.5 / self.fps() + 1e-9 else None

    def delete_key(self, all_joints=False):
        """Delete the selected joint's (or all joints') key at the current time."""
        joints = self.edits.scope(all_joints)
        k = self._near_key(joints)
        if k is None:
            return 0
        return self.edits.edit_clip(f"Delete key at {k:.2f}s",
                                    lambda c: c.delete_keys([k], joints))

    def move_key(self, old, new, all_joints=False):
        """Move the key at ``old`` seconds to ``new`` (selected joint, or all)."""
        joints = self.edits.scope(all_joints)
        new = float(min(max(new, 0.0), self.edits.duration()))
        return self.edits.edit_clip(f"Move key {old:.2f}s -> {new:.2f}s",
                                    lambda c: c.move_keys({old: new}, joints))

    def copy_keys(self, all_joints=False):
        """Copy the selected joint's (or all) values at the current time."""
        if self.edits.clip is not None:
            self.clipboard = self.edits.clip.copy_keys(self.document.time,
                                                       self.edits.scope(all_joints))
        return self.clipboard

    def paste_keys(self):
        """Paste copied values as keys at the current time."""
        if not self.clipboard or self.edits.clip is None:
            return 0
        data = {k: v for k, v in self.clipboard.items() if k[0] in self.document.skeleton.index}
        t = self.document.time
        return self.edits.edit_clip(f"Paste keys at {t:.2f}s", lambda c: c.paste_keys(data, t))

    def set_interpolation(self, mode, channel="rotation"):
        """Interpolation of the selected joint's (or all) ``rotation`` or ``vector``
        (translation and scale) tracks."""
        name = self.edits.joint_name()
        channels = ("rotation",) if channel == "rotation" else ("translation", "scale")

        def change(c):
            return sum(c.set_interpolation(mode, joint=name, channel=ch) for ch in channels)

        try:
            return self.edits.edit_clip(f"Interpolation {mode}", change)
        except ValueError as exc:
            self.error(str(exc))
            return 0

    # ------------------------------------------------------------------ key drags
    def key_drag_start(self, t, all_joints):
        """The ruler started dragging the key mark at ``t`` (of every joint, or the
        selected one's)."""
        self.pause()
        clip = self.edits.clip
        if clip is None:
            return
        joints = None if all_joints else self.edits.scope(False)
        self._drag = {"clip": clip, "before": clip.state(), "old": t, "new": t,
                      "joints": joints}
        self.seek(t)

    def key_drag_move(self, t):
        """The dragged key is at ``t``: the clip shows it there (not yet an undo step)."""
        drag = self._drag
        if drag is None or t == drag["new"]:
            return
        clip = drag["clip"]
        clip.restore(drag["before"])
        clip.move_keys({drag["old"]: t}, drag["joints"])
        drag["new"] = t
        self.show_time(t)

    def key_drag_end(self):
        """The drag ended: the whole move becomes one undo step."""
        drag, self._drag = self._drag, None
        if drag is None or drag["new"] == drag["old"]:
            return
        clip = drag["clip"]
        clip.restore(drag["before"])
        self.edits.edit_clip(f"Move key {drag['old']:.2f}s -> {drag['new']:.2f}s",
                             lambda c: c.move_keys({drag["old"]: drag["new"]}, drag["joints"]),
                             clip=clip)

    # ------------------------------------------------------------------ auto-key
    def _changed_joints(self):
        clip, pose = self.edits.clip, self.document.pose
        ref = clip.sample(self.document.time)
        moved = (~np.all(np.isclose(pose.translation, ref.translation, atol=1e-7), axis=1)
                 | ~np.all(np.isclose(pose.scale, ref.scale, atol=1e-7), axis=1)
                 | (np.abs(np.sum(pose.rotation * ref.rotation, axis=1)) < 1 - 1e-9))
        return [self.document.skeleton.names[j] for j in np.flatnonzero(moved)]

    def maybe_auto_key(self):
        """Called on each undo-stack change: key what a new pose edit moved, when on."""
        n = len(self.document.undo_stack)
        grew, self.edits.stack_len = n > self.edits.stack_len, n
        # a new pose edit (not ours, not an undo) while auto-key is on: key what it moved
        if (grew and not self.edits.own_push and self.auto_key and self.edits.clip is not None
                and self.document.mode == "pose" and not self.document.dragging):
            joints = self._changed_joints()
            if joints:
                # one undo step for the pose edit and its keys, as the user made one edit
                last = self.document.undo_stack.undo_label
                self.insert_key(joints=joints, amend=True,
                                label=f"{last} + auto-key {', '.join(joints)}")
