"""The editor's last line against lost errors: a ``sys.excepthook`` that shows and logs.

An exception that escapes a Qt slot reaches ``sys.excepthook`` (PyQt5 aborts the process
when the hook is Python's default one); VTK observers and job completion callbacks report
theirs through :func:`report`. Each one is

- logged with its traceback to ``rigedit.log`` in the user's cache folder
  (:func:`rigedit.editor.recovery.log_path`; the traceback goes there only),
- shown to the user by the newest live editor window (``window.show_unexpected_error``:
  a red status message naming what failed and a non-modal dialog; the window also writes a
  recovery snapshot, as the state after an unexpected error may not be trustworthy),
- and handed on to the hook that was installed before, unless that is Python's default
  (which would print the traceback to the terminal): under pytest-qt that hook records it,
  so a test still fails on an unexpected exception.

The process keeps running.
"""
from __future__ import annotations

import faulthandler
import logging
import logging.handlers
import os
import sys
import traceback

from PyQt5 import QtWidgets

from ..editor import recovery

__all__ = ["install", "uninstall", "report", "describe", "logger", "enable_faulthandler",
           "ErrorDisplay"]

_LOG = logging.getLogger("rigedit")
_windows = []      # live editor windows, newest last
_previous = None   # the hook before ours
_faults = None     # the file faulthandler writes to


def logger():
    """The ``rigedit`` logger, writing to :func:`rigedit.editor.recovery.log_path` (1 MB, one
    older file kept). When the cache folder cannot be written the log goes nowhere rather
    than failing the editor."""
    path = recovery.log_path()
    for h in _LOG.handlers:
        if getattr(h, "baseFilename", None) == str(path):
            return _LOG
    for h in list(_LOG.handlers):  # the cache folder moved (another XDG_CACHE_HOME)
        if getattr(h, "_rigedit", False):
            _LOG.removeHandler(h)
            h.close()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        handler = logging.handlers.RotatingFileHandler(path, maxBytes=1 << 20, backupCount=1,
                                                       encoding="utf-8", delay=True)
    except OSError:
        return _LOG
    handler._rigedit = True
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s [pid %(process)d] "
                                           "%(message)s"))
    _LOG.addHandler(handler)
    _LOG.setLevel(logging.INFO)
    _LOG.propagate = False  # the terminal gets no traceback
    return _LOG


def describe(exc_type, exc, tb):
    """One line naming the error and where it happened: the innermost frame in rigedit's
    own code (or the innermost at all), ``"ZeroDivisionError: division by zero (in
    timeline.py:123, _on_key)"``."""
    frames = traceback.extract_tb(tb) if tb is not None else []
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    own = [f for f in frames if os.path.abspath(f.filename).startswith(root)
           or f.filename.endswith("app.py")]
    where = (own or frames or [None])[-1]
    message = " ".join(str(exc).split())  # one line, whatever the exception's text
    if len(message) > 300:
        message = message[:297] + "..."
    text = f"{exc_type.__name__}: {message}" if message else exc_type.__name__
    if where is not None:
        text += f" (in {os.path.basename(where.filename)}:{where.lineno}, {where.name})"
    return text


def report(what=None, exc_info=None):
    """Log and show an exception (the one being handled by default) that rigedit's own
    code caught where it must not propagate (a VTK observer, a job's completion callback).
    ``what`` names the failed operation ("Re-binding after moving knee_L")."""
    exc_info = exc_info or sys.exc_info()
    _handle(exc_info, what)


def _hook(exc_type, exc, tb):
    if issubclass(exc_type, KeyboardInterrupt):
        (_previous or sys.__excepthook__)(exc_type, exc, tb)
        return
    _handle((exc_type, exc, tb), None)


def _handle(exc_info, what):
    exc_type, exc, tb = exc_info
    summary = describe(exc_type, exc, tb)
    try:
        logger().error("%s: %s", f"{what} failed" if what else "Unexpected error", summary,
                       exc_info=exc_info)
    except Exception:  # noqa: BLE001 - the hook itself must never raise
        pass
    shown = False
    for window in reversed(_windows):
        try:
            window.show_unexpected_error(what, summary)
            shown = True
            break
        except Exception:  # noqa: BLE001 - a half-closed window: try the next one
            logger().error("showing an error failed", exc_info=True)
    if _previous is not None and _previous is not sys.__excepthook__ and _previous is not _hook:
        _previous(exc_type, exc, tb)
    elif not shown:  # no window to show it: the terminal is the only place left
        sys.__excepthook__(exc_type, exc, tb)


def install(window):
    """Route unexpected exceptions to ``window`` (and log them) until :func:`uninstall`."""
    global _previous
    if not _windows:
        _previous = sys.excepthook
        sys.excepthook = _hook
    _windows.append(window)


def uninstall(window):
    """Stop routing to ``window``; the previous hook comes back with the last window."""
    global _previous
    if window in _windows:
        _windows.remove(window)
    if not _windows and sys.excepthook is _hook:
        sys.excepthook = _previous or sys.__excepthook__
        _previous = None


def enable_faulthandler():
    """Dump the Python stack of a hard crash (a segmentation fault in VTK or Qt) into the
    log file, where no Python code could run to report it."""
    global _faults
    if _faults is not None:
        return
    try:
        path = recovery.log_path()
        path.parent.mkdir(parents=True, exist_ok=True)
        _faults = open(path, "a", encoding="utf-8")  # noqa: SIM115 - open for the process
    except OSError:
        return
    faulthandler.enable(file=_faults)


class ErrorDisplay:
    """How a window shows unexpected errors (``status_bar``: its status bar; ``parent``: the
    dialog's parent): a red label in the status bar that stays (the
    status line itself is overwritten by the next "Posed knee_L") naming what failed, and one
    non-modal dialog, reused while it is open, with a count.

    Attributes
    ----------
    label : QLabel
        The red status bar label (hidden until an error; hidden again when the dialog is
        dismissed).
    dialog : QMessageBox or None
    count : int
        Unexpected errors so far.
    """

    def __init__(self, status_bar, parent):
        self.status_bar = status_bar
        self.parent = parent
        self.count = 0
        self.dialog = None
        self.label = QtWidgets.QLabel()
        self.label.setStyleSheet("color: #ff6b6b; font-weight: bold")
        self.label.setVisible(False)
        self.label.setMaximumWidth(640)  # long messages are cut; the tooltip has it all
        status_bar.insertPermanentWidget(0, self.label)

    def show(self, what, summary, saved=False):
        """Show one error: ``what`` failed (None: not known, as for a Qt slot, whose
        function ``summary`` names) with ``summary`` from :func:`describe`."""
        log = recovery.log_path()
        self.count += 1
        headline = f"Error: {what} failed: {summary}" if what else \
            f"Unexpected error: {summary}"
        self.label.setText(headline)
        self.label.setToolTip(f"{headline}\nDetails in {log}")
        self.label.setVisible(True)
        self.status_bar.showMessage(f"Error; details in {log}")
        text = (f"{what} failed unexpectedly:\n{summary}" if what
                else f"An unexpected error happened:\n{summary}")
        text += ("\n\n" + ("Your work was written to a recovery file. " if saved else "")
                 + f"The details are in {log}.")
        if self.count > 1:
            text += f"\n\n({self.count} errors so far)"
        box = self.dialog
        if box is None or not box.isVisible():
            box = QtWidgets.QMessageBox(QtWidgets.QMessageBox.Critical, "rigedit: error", "",
                                        QtWidgets.QMessageBox.Ok, self.parent)
            box.setModal(False)  # the editor stays usable (and can be saved) behind it
            box.finished.connect(lambda _: self.label.setVisible(False))
            self.dialog = box
        box.setText(text)
        box.show()
