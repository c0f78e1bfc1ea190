"""Clip edits as undo steps: one :class:`ClipCommand` per user action.

:func:`edit_clip` snapshots a clip (``Clip.state``, cheap because tracks are immutable) before
and after a change and pushes one command that restores either snapshot; :func:`edit_clips`
does the same for the clip list and the current clip. Edits that changed nothing record
nothing. Doing or undoing one tells the document (:meth:`Document.clip_changed`), which samples
the pose again and announces KeysChanged or ClipChanged. The key and clip commands
(:mod:`.key_commands`, :mod:`.clip_commands`) are written with these two.
"""
from __future__ import annotations

from .events import KeysChanged
from .undo import Command

__all__ = ["ClipCommand", "edit_clip", "edit_clips"]


class ClipCommand(Command):
    """A :class:`Command` that edits clips, so the auto-key can tell clip edits (which it
    must not answer with keys) from pose edits."""

    __slots__ = ()


def _push(document, command, amend):
    if amend:   # fold into the last step (the auto-key's keys join the pose edit's step)
        document.undo_stack.amend(command)
    else:
        document.push(command)


def _same(before, after):
    """Whether two ``Clip.state`` snapshots hold the same tracks (by identity) and fields."""
    return (before[1:] == after[1:] and before[0].keys() == after[0].keys()
            and all(before[0][k] is after[0][k] for k in before[0]))


def edit_clip(document, label, change, resample=True, clip=None, amend=False):
    """Run ``change(clip)`` on ``clip`` (default: the current one) as one undo step.

    Parameters
    ----------
    document : Document
    label : str
        The undo step's text.
    change : callable(Clip)
        Edits the clip in place; what it returns is returned.
    resample : bool
        Whether the pose is sampled from the clip again after the edit (False for a key
        written from the current pose: the pose's other joints keep what the user set).
        Undo and redo always sample again.
    clip : Clip, optional
    amend : bool
        Fold the step into the last one (one undo reverts both).

    Returns
    -------
    object
        What ``change`` returned; None without a clip. Nothing is recorded when the clip did
        not change.
    """
    clip = clip or document.clip
    if clip is None:
        return None
    before = clip.state()
    result = change(clip)
    after = clip.state()
    if _same(before, after):
        return result
    clip.restore(before)
    first = [True]

    def do():
        clip.restore(after)
        # only the first time may keep the pose (a redo shows the clip's pose again)
        document.clip_changed(KeysChanged(clip.name), resample or not first[0])
        first[0] = False

    def undo():
        clip.restore(before)
        document.clip_changed(KeysChanged(clip.name), True)

    _push(document, ClipCommand(label, do, undo), amend)
    return result


def edit_clips(document, label, change):
    """Run ``change()`` (which edits ``document.clips`` and returns the name of the clip to
    make current) as one undo step; the clips' names follow their keys. Returns that name."""
    d = document
    before = (dict(d.clips), d.current_clip)
    current = change()
    after = (dict(d.clips), current)

    def restore(clips):
        d.clips.clear()
        d.clips.update(clips)
        for key, clip in clips.items():
            clip.name = key

    def apply(state):
        restore(state[0])
        d.set_current_clip(state[1])

    restore(before[0])   # silently: the command's do makes the change again, announced
    d.push(ClipCommand(label, lambda: apply(after), lambda: apply(before)))
    return current
