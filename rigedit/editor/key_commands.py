"""Key edits of the document's current clip, each one undo step (:func:`.clip_edits.edit_clip`):
set keys from the pose, delete, move, copy and paste keys, set the interpolation.

``joints`` is a list of joint names or indices, or None for every joint; ``t`` defaults to the
document's time. The timeline's :class:`~rigedit.editor.timeline_keys.KeyEditor` calls these
with the selected joint and its frame rate.
"""
from __future__ import annotations

import numpy as np

from .clip_edits import edit_clip

__all__ = ["set_key", "key_near", "delete_key", "move_keys", "KeyDrag", "copy_keys",
           "paste_keys", "set_interpolation", "changed_joints", "DEFAULT_TOLERANCE"]

#: How near (seconds) a key must be to a time to be "at" it: half a frame at 30 fps.
DEFAULT_TOLERANCE = 0.5 / 30


def _names(document, joints):
    """Joint names from names or indices (None stays None: all joints)."""
    if joints is None:
        return None
    sk = document.skeleton
    return [sk.names[sk.joint_index(j)] for j in joints]


def _time(document, t):
    return document.time if t is None else float(t)


def set_key(document, joints=None, t=None, label=None, amend=False):
    """Key ``joints`` at ``t`` from the current pose; a document without a clip gets a new
    one first (its own undo step). Returns the number of channels keyed."""
    from .clip_commands import new_clip

    if document.clip is None:
        new_clip(document)
    names, t = _names(document, joints), _time(document, t)
    what = "all joints" if names is None else ", ".join(names)
    pose = document.pose
    return edit_clip(document, label or f"Key {what} at {t:.2f}s",
                     lambda c: c.key_pose(pose, t, names), resample=False, amend=amend)


def key_near(document, joints=None, t=None, tolerance=DEFAULT_TOLERANCE):
    """The time of the key of ``joints`` nearest ``t``, when within ``tolerance`` seconds;
    else None."""
    clip = document.clip
    if clip is None:
        return None
    names, t = _names(document, joints), _time(document, t)
    times = clip.key_times() if names is None else np.unique(np.concatenate(
        [clip.key_times(j) for j in names]))
    if len(times) == 0:
        return None
    k = times[np.argmin(np.abs(times - t))]
    return float(k) if abs(k - t) <= tolerance + 1e-9 else None


def delete_key(document, joints=None, t=None, tolerance=DEFAULT_TOLERANCE):
    """Delete the key of ``joints`` at ``t`` (within ``tolerance``). Returns the number of
    keys deleted."""
    names = _names(document, joints)
    k = key_near(document, names, t, tolerance)
    if k is None:
        return 0
    return edit_clip(document, f"Delete key at {k:.2f}s", lambda c: c.delete_keys([k], names))


def move_keys(document, moves, joints=None):
    """Move keys: ``moves`` is ``{old time: new time}``, new times clamped to the clip (a key
    that would stay where it is is not moved). Returns the number of tracks changed."""
    clip = document.clip
    if clip is None:
        return 0
    end = clip.duration if clip.duration > 0 else 1.0
    moves = {float(old): float(min(max(new, 0.0), end)) for old, new in moves.items()}
    moves = {old: new for old, new in moves.items() if old != new}
    if not moves:
        return 0
    label = ("Move keys" if len(moves) != 1 else
             "Move key {:.2f}s -> {:.2f}s".format(*next(iter(moves.items()))))
    names = _names(document, joints)
    return edit_clip(document, label, lambda c: c.move_keys(moves, names))


class KeyDrag:
    """A key dragged along the time line (the ruler's key marks): the clip shows the key where
    it is dragged at once, and :meth:`end` makes the whole move one undo step.

    Parameters
    ----------
    document : Document
        Its current clip; the document's time follows the key as it moves.
    t : float
        The time of the key grabbed.
    joints : list or None
        Whose keys move (None: every joint's at ``t``).
    """

    def __init__(self, document, t, joints=None):
        self.document = document
        self.clip = document.clip
        self.before = None if self.clip is None else self.clip.state()
        self.old = self.new = float(t)
        self.joints = _names(document, joints)

    def move(self, t):
        """The key is at ``t`` seconds now: the clip and the pose show it there (no undo
        step yet)."""
        t = float(t)
        if self.clip is None or t == self.new:
            return
        self.clip.restore(self.before)
        self.clip.move_keys({self.old: t}, self.joints)
        self.new = t
        self.document.set_time(t)

    def end(self):
        """Release: one undo step for the whole move (none when the key is back where it
        was, or the clip is no longer the current one). Returns the tracks changed."""
        if self.clip is None or self.new == self.old:
            return 0
        self.clip.restore(self.before)
        if self.clip is not self.document.clip:
            return 0
        return move_keys(self.document, {self.old: self.new}, self.joints)


def copy_keys(document, joints=None, t=None):
    """The values of ``joints``' tracks at ``t``, for :func:`paste_keys`: ``{(joint,
    channel): value}`` (empty without a clip)."""
    clip = document.clip
    return {} if clip is None else clip.copy_keys(_time(document, t), _names(document, joints))


def paste_keys(document, data, t=None):
    """Key copied values (:func:`copy_keys`) at ``t``; those of joints this skeleton lacks
    are left out. Returns the number of keys set."""
    if not data or document.clip is None:
        return 0
    data = {k: v for k, v in data.items() if k[0] in document.skeleton.index}
    t = _time(document, t)
    return edit_clip(document, f"Paste keys at {t:.2f}s", lambda c: c.paste_keys(data, t))


def set_interpolation(document, mode, joint=None, channel="rotation"):
    """The interpolation of ``joint``'s (every joint's when None) ``"rotation"`` tracks, or
    of its ``"vector"`` ones (translation and scale). ``ValueError`` for a mode a track does
    not take (nothing changed). Returns the number of tracks set."""
    name = None if joint is None else _names(document, [joint])[0]
    channels = ("rotation",) if channel == "rotation" else ("translation", "scale")

    def change(c):
        return sum(c.set_interpolation(mode, joint=name, channel=ch) for ch in channels)

    return edit_clip(document, f"Interpolation {mode}", change)


def changed_joints(document):
    """Names of the joints whose pose differs from the current clip at the current time."""
    pose = document.pose
    ref = document.clip.sample(document.time)
    moved = (~np.all(np.isclose(pose.translation, ref.translation, atol=1e-7), axis=1)
             | ~np.all(np.isclose(pose.scale, ref.scale, atol=1e-7), axis=1)
             | (np.abs(np.sum(pose.rotation * ref.rotation, axis=1)) < 1 - 1e-9))
    return [document.skeleton.names[j] for j in np.flatnonzero(moved)]
