"""The clip list's edits: new, add, rename, duplicate and delete a clip, and a clip's duration.

Each is one undo step (:mod:`.clip_edits`). Names are checked as everywhere a clip is made
(:mod:`rigedit.animation.clip_names`); a refused name raises ``ValueError`` saying why, which
the timeline shows instead of raising.
"""
from __future__ import annotations

from ..animation.clip import Clip
from ..animation.clip_names import check_new_clip_name, name_key
from .clip_edits import edit_clip, edit_clips

__all__ = ["unique_clip_name", "new_clip", "add_clip", "rename_clip", "duplicate_clip",
           "delete_clip", "set_duration"]


def unique_clip_name(document, base):
    """``base``, or ``base 2``, ``base 3``, ...: the first that no clip has (ignoring case,
    see :mod:`rigedit.animation.clip_names`)."""
    taken = {name_key(n) for n in document.clips}
    name, i = base, 2
    while name_key(name) in taken:
        name, i = f"{base} {i}", i + 1
    return name


def new_clip(document, name=None, duration=2.0):
    """Add an empty clip of ``duration`` seconds and make it current. Returns its name
    (``name`` made unique, ``"clip"`` by default)."""
    clip = Clip("clip", document.skeleton, {}, duration=duration)
    return add_clip(document, clip, name or "clip", lambda n: f"New clip {n}")


def add_clip(document, clip, base, label):
    """Add ``clip`` (on the document's skeleton) under ``base`` made unique, as one undo
    step, and make it current. ``label`` is the undo step's text, or a function of the name.
    Returns the name."""
    name = check_new_clip_name(unique_clip_name(document, base), document.clips)
    clip.name = name

    def change():
        document.clips[name] = clip
        return name

    edit_clips(document, label(name) if callable(label) else label, change)
    return name


def rename_clip(document, new, old=None):
    """Rename clip ``old`` (default: the current one) to ``new``. Returns the name it has,
    or None without a clip."""
    old = document.current_clip if old is None else old
    if old is None:
        return None
    new = str(new).strip()
    if new == old:
        return old
    check_new_clip_name(new, document.clips, old=old)
    current = document.current_clip

    def change():
        clips = document.clips
        items = [(new if k == old else k, c) for k, c in clips.items()]
        clips.clear()
        clips.update(items)
        return new if current == old else current

    edit_clips(document, f"Rename clip {old} -> {new}", change)
    return new


def duplicate_clip(document):
    """Add a copy of the current clip and make it current. Returns its name, or None."""
    clip = document.clip
    if clip is None:
        return None
    return add_clip(document, clip.copy(), f"{clip.name} copy", f"Duplicate clip {clip.name}")


def delete_clip(document, name=None):
    """Delete clip ``name`` (default: the current one); when it was current, the first
    remaining one becomes current. Returns the deleted clip's name, or None."""
    old = document.current_clip if name is None else name
    if old is None or old not in document.clips:
        return None
    current = document.current_clip

    def change():
        del document.clips[old]
        return next(iter(document.clips), None) if current == old else current

    edit_clips(document, f"Delete clip {old}", change)
    return old


def set_duration(document, duration):
    """Set the current clip's duration in seconds as one undo step (the document's time is
    left where it is: sampling clamps or wraps it). Returns whether it changed."""
    clip = document.clip
    if clip is None or abs(duration - clip.duration) < 1e-9:
        return False
    edit_clip(document, f"Duration {duration:g}s", lambda c: c.set_duration(duration))
    return True
