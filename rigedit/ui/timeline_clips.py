"""The timeline's clip list: new, add, rename, duplicate and delete a clip, its duration.

Each is one undo step (:class:`~rigedit.editor.timeline_edits.ClipEdits`); names are checked
as everywhere a clip is made (:mod:`rigedit.animation.clip_names`) and a refused name is
reported, not raised.
"""
from __future__ import annotations

from PyQt5 import QtWidgets

from ..animation.clip import Clip
from ..animation.clip_names import check_new_clip_name, name_key

__all__ = ["ClipManager"]


class ClipManager:
    """The document's clips as the timeline edits them.

    Parameters
    ----------
    document : Document
    edits : ClipEdits
        The current clip and the undo steps.
    parent : QtWidgets.QWidget
        Parent of the rename dialog.
    pause : callable()
        Stops playback (before a clip is deleted).
    seek : callable(t)
        Moves the timeline to ``t`` seconds (when a shorter duration cuts the current time).
    error : callable(message)
        Shows why a name was refused.
    """

    def __init__(self, document, edits, parent, pause, seek, error):
        self.document = document
        self.edits = edits
        self.parent = parent
        self.pause = pause
        self.seek = seek
        self.error = error

    def _unique(self, base):
        """``base``, or ``base 2``, ``base 3``, ...: the first that no clip has (ignoring
        case, see :mod:`rigedit.animation.clip_names`)."""
        taken = {name_key(n) for n in self.document.clips}
        name, i = base, 2
        while name_key(name) in taken:
            name, i = f"{base} {i}", i + 1
        return name

    def _valid_name(self, name, old=None):
        """``name`` when the rig can take it, else None with the reason shown (status bar)."""
        try:
            return check_new_clip_name(name, self.document.clips, old=old)
        except ValueError as exc:
            self.error(str(exc))
            return None

    def new_clip(self, name=None, duration=2.0):
        """Add an empty clip and make it current. Returns its name, or None (and an error
        in the status bar) for an invalid name."""
        clip = Clip("clip", self.document.skeleton, {}, duration=duration)
        return self.add_clip(clip, name or "clip", lambda n: f"New clip {n}")

    def add_clip(self, clip, base, label):
        """Add ``clip`` (on the document's skeleton) under ``base`` made unique, as one undo
        step, and make it current. ``label`` is the undo step's text, or a function of the
        name. Returns the name, or None (and an error in the status bar) for an invalid name."""
        name = self._valid_name(self._unique(base))
        if name is None:
            return None
        clip.name = name

        def change():
            self.document.clips[name] = clip
            return name

        self.edits.edit_clips(label(name) if callable(label) else label, change)
        return name

    def rename_clip(self, new=None):
        """Rename the current clip to ``new`` (asked in a dialog when None). Returns the
        name it has, or None when cancelled or refused."""
        old = self.document.current_clip
        if old is None:
            return None
        if new is None:
            new, ok = QtWidgets.QInputDialog.getText(self.parent, "Rename clip", "Name:",
                                                     text=old)
            if not ok:
                return None
        new = str(new).strip()
        if new == old:
            return old
        if self._valid_name(new, old=old) is None:
            return None

        def change():
            clips = self.document.clips
            items = [(new if k == old else k, c) for k, c in clips.items()]
            clips.clear()
            clips.update(items)
            return new

        self.edits.edit_clips(f"Rename clip {old} -> {new}", change)
        return new

    def duplicate_clip(self):
        """Add a copy of the current clip and make it current. Returns its name."""
        clip = self.edits.clip
        if clip is None:
            return None
        return self.add_clip(clip.copy(), f"{clip.name} copy", f"Duplicate clip {clip.name}")

    def delete_clip(self):
        """Delete the current clip (the first remaining one becomes current). Returns the
        deleted clip's name."""
        old = self.document.current_clip
        if old is None:
            return None

        def change():
            del self.document.clips[old]
            return next(iter(self.document.clips), None)

        self.pause()
        self.edits.edit_clips(f"Delete clip {old}", change)
        return old

    def set_duration(self, duration):
        """Set the current clip's duration in seconds as one undo step; a current time
        past the new end moves to it."""
        clip = self.edits.clip
        if clip is None or abs(duration - clip.duration) < 1e-9:
            return
        self.edits.edit_clip(f"Duration {duration:g}s", lambda c: c.set_duration(duration))
        if self.document.time > duration:
            self.seek(duration)
