"""What the window tells the user: the status line, one clear message for bad input, and
unexpected errors (bugs) shown through :class:`~.errors_hook.ErrorDisplay` after a recovery
save."""
from __future__ import annotations

import sys

from PyQt5 import QtCore, QtWidgets

from . import errors_hook

__all__ = ["Messages"]


class Messages:
    """The status line and the error messages of a window.

    Parameters
    ----------
    status_bar : QStatusBar
    parent : QWidget
        The dialogs' parent.
    crash_save : callable
        ``crash_save() -> bool``: write the document for recovery (whether it holds the last
        edit), before a bug is shown (:meth:`Autosave.crash_save
        <rigedit.ui.autosave.Autosave.crash_save>`).

    Attributes
    ----------
    display : ErrorDisplay
    last_error : str or None
        The last error message shown.
    last_dialog : QMessageBox or None
        The last message box of :meth:`error`.
    """

    def __init__(self, status_bar, parent, crash_save):
        self.status_bar = status_bar
        self.parent = parent
        self.crash_save = crash_save
        self.display = errors_hook.ErrorDisplay(status_bar, parent)
        self.last_error = None
        self.last_dialog = None

    def status(self, text, timeout=0):
        self.status_bar.showMessage(text, timeout)

    def error(self, title, message):
        """Show one clear message: a dialog (not blocking) and the status bar."""
        self.last_error = message
        self.status(f"Error: {message}")
        box = QtWidgets.QMessageBox(QtWidgets.QMessageBox.Warning, title, message,
                                    QtWidgets.QMessageBox.Ok, self.parent)
        box.setAttribute(QtCore.Qt.WA_DeleteOnClose)
        box.open()
        self.last_dialog = box

    def report_exception(self, what=None):
        """Log and show the exception being handled (see :mod:`.errors_hook`); for code that
        must not let it propagate (VTK observers, job callbacks)."""
        errors_hook.report(what, sys.exc_info())

    def show_unexpected_error(self, what, summary):
        """Called by :mod:`.errors_hook` for a bug (not bad input): the document is written
        for recovery first, as the state after a bug may not be trustworthy; then
        :class:`~.errors_hook.ErrorDisplay` shows it."""
        saved = self.crash_save()
        self.last_error = f"{what} failed: {summary}" if what else summary
        self.display.show(what, summary, saved)
