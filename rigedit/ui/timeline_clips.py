"""The timeline's clip list: new, add, rename, duplicate and delete a clip, its duration.

Each is a clip command of the editor (:mod:`rigedit.editor.clip_commands`, one undo step);
here a refused name is reported instead of raised, and Rename asks for the name in a dialog.
"""
from __future__ import annotations

from PyQt5 import QtWidgets

from ..editor import clip_commands

__all__ = ["ClipManager"]


class ClipManager:
    """The document's clips as the timeline edits them.

    Parameters
    ----------
    document : Document
    parent : QtWidgets.QWidget
        Parent of the rename dialog.
    pause : callable()
        Stops playback (before a clip is deleted).
    seek : callable(t)
        Moves the timeline to ``t`` seconds (when a shorter duration cuts the current time).
    error : callable(message)
        Shows why a name was refused.
    """

    def __init__(self, document, parent, pause, seek, error):
        self.document = document
        self.parent = parent
        self.pause = pause
        self.seek = seek
        self.error = error

    def _reported(self, command, *args):
        """``command(document, *args)``, or None with the reason shown when it refused."""
        try:
            return command(self.document, *args)
        except ValueError as exc:
            self.error(str(exc))
            return None

    def new_clip(self, name=None, duration=2.0):
        """Add an empty clip and make it current. Returns its name, or None (and an error
        in the status bar) for an invalid name."""
        return self._reported(clip_commands.new_clip, name, duration)

    def add_clip(self, clip, base, label):
        """Add ``clip`` (on the document's skeleton) under ``base`` made unique, as one undo
        step, and make it current. ``label`` is the undo step's text, or a function of the
        name. Returns the name, or None (and an error in the status bar) for an invalid name."""
        return self._reported(clip_commands.add_clip, clip, base, label)

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
        return self._reported(clip_commands.rename_clip, new)

    def duplicate_clip(self):
        """Add a copy of the current clip and make it current. Returns its name."""
        return self._reported(clip_commands.duplicate_clip)

    def delete_clip(self):
        """Delete the current clip (the first remaining one becomes current). Returns the
        deleted clip's name."""
        if self.document.current_clip is None:
            return None
        self.pause()
        return clip_commands.delete_clip(self.document)

    def set_duration(self, duration):
        """Set the current clip's duration in seconds as one undo step; a current time
        past the new end moves to it."""
        if clip_commands.set_duration(self.document, duration) and self.document.time > duration:
            self.seek(duration)
