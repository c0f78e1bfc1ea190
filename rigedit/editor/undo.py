"""Undo history: :class:`Command` (one undoable edit) and :class:`UndoStack`. Pure Python.

The stack also keeps the facts that autosave and the title bar ask about: a revision counter
that changes with every change of the history, and the command whose state is current
(:attr:`UndoStack.top`), against which :class:`~rigedit.editor.document.Document` tells whether
there are unsaved changes.
"""
from __future__ import annotations

__all__ = ["Command", "UndoStack"]


class Command:
    """One undoable edit.

    Parameters
    ----------
    label : str
        Shown in the Edit menu ("Undo Rotate knee_L").
    do, undo : callable
        Apply and revert the edit; ``do`` is called when the command is pushed (unless told
        otherwise) and on redo.
    """

    __slots__ = ("label", "do", "undo")

    def __init__(self, label, do, undo):
        self.label = str(label)
        self.do = do
        self.undo = undo

    def __repr__(self):
        return f"Command({self.label!r})"


class UndoStack:
    """A linear undo history of :class:`Command` objects.

    Parameters
    ----------
    limit : int
        Oldest commands are dropped past this many.
    """

    def __init__(self, limit=200):
        self.limit = int(limit)
        self._done = []
        self._undone = []
        self.observers = []
        #: Counts every change of the history (push, amend, undo, redo, clear), so a reader
        #: such as the autosave can tell "changed since I last looked" with one integer.
        self.revision = 0
        #: What the last change of the history was: "push", "amend", "undo", "redo" or
        #: "clear" (None before any). The auto-key keys after a push, never after an undo.
        self.last_action = None

    def push(self, command, execute=True):
        """Record ``command``; run its ``do`` first unless ``execute`` is false (for edits
        already applied, such as a finished drag). Clears the redo history."""
        if execute:
            command.do()
        self._done.append(command)
        del self._done[:-self.limit]
        self._undone.clear()
        self._notify("push")

    def amend(self, command, label=None, execute=True):
        """Run ``command`` and fold it into the last step, so one undo reverts both (an
        auto-key written after the pose edit that caused it). Pushes it alone when the stack
        is empty."""
        if not self._done:
            return self.push(command, execute)
        if execute:
            command.do()
        last = self._done.pop()

        def do():
            last.do()
            command.do()

        def undo():
            command.undo()
            last.undo()

        self._done.append(Command(label or f"{last.label} + {command.label}", do, undo))
        self._undone.clear()
        self._notify("amend")

    def undo(self):
        """Revert the last command; returns it, or None when there is nothing to undo."""
        if not self._done:
            return None
        cmd = self._done.pop()
        cmd.undo()
        self._undone.append(cmd)
        self._notify("undo")
        return cmd

    def redo(self):
        """Re-apply the last undone command; returns it or None."""
        if not self._undone:
            return None
        cmd = self._undone.pop()
        cmd.do()
        self._done.append(cmd)
        self._notify("redo")
        return cmd

    def clear(self):
        self._done.clear()
        self._undone.clear()
        self._notify("clear")

    @property
    def top(self):
        """The command whose state is current (the last one done), or None."""
        return self._done[-1] if self._done else None

    @property
    def can_undo(self):
        return bool(self._done)

    @property
    def can_redo(self):
        return bool(self._undone)

    @property
    def undo_label(self):
        return self._done[-1].label if self._done else ""

    @property
    def redo_label(self):
        return self._undone[-1].label if self._undone else ""

    def __len__(self):
        return len(self._done)

    def _notify(self, action):
        self.revision += 1
        self.last_action = action
        for cb in list(self.observers):
            cb()
