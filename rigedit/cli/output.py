"""Output files of the ``rigedit`` command: checked before any work, and never left half
written when the run is interrupted.

- :func:`check_output` refuses, up front and with the user's path in the message, an output
  whose folder does not exist (no command creates folders) or a file output that is a folder.
- :func:`interruptible` turns SIGINT (Ctrl-C) and SIGTERM into an :class:`Interrupted`
  exception, so the writers' clean-up (``finally`` blocks that delete their temporary file)
  runs; the command then prints one line and exits with 128 + the signal number (130, 143).
  Within :func:`deferred` (rendering) a signal is only recorded, and the job raises it at
  its next step with :func:`check_interrupted`: an exception raised while Python code runs
  inside VTK (a ``vtkPythonAlgorithm``) is printed and swallowed there, and one raised while
  imageio starts ffmpeg can leave ffmpeg to create the temporary file after the clean-up.
"""
from __future__ import annotations

import contextlib
import signal
import sys
import threading
import warnings
from pathlib import Path

from ..errors import RigFileError
from ..io.atomic import check_output_folder

__all__ = ["Interrupted", "interruptible", "check_interrupted", "deferred", "check_output",
           "warning_lines", "quiet_warnings", "warn"]

#: Signals received within :func:`interruptible`, oldest first.
_received = []
#: True within :func:`deferred`.
_deferring = [False]
#: True within :func:`quiet_warnings` (``-q``).
_quiet = [False]


class Interrupted(BaseException):
    """The run got SIGINT or SIGTERM. A ``BaseException``, like ``KeyboardInterrupt``, so that
    ``except Exception`` in the middle of a job does not swallow it, and for that reason not
    a :class:`rigedit.progress.Cancelled` (an ``Exception``): the command's progress
    callables raise it at a job's step boundary (:func:`check_interrupted`) where a window's
    would raise ``Cancelled``, and the job lets it through the same way."""

    def __init__(self, signum):
        self.signum = signum
        super().__init__(signal.Signals(signum).name)

    @property
    def exit_status(self):
        return 128 + self.signum


def _raise_interrupted(signum, frame):
    # Only the first signal raises: a second Ctrl-C must not break into the clean-up that the
    # first one started (and leave the temporary file behind).
    _received.append(signum)
    if len(_received) == 1 and not _deferring[0]:
        raise Interrupted(signum)


def check_interrupted():
    """Raise :class:`Interrupted` when a signal came (held by :func:`deferred`, or raised
    once and swallowed by a VTK callback)."""
    if _received:
        raise Interrupted(_received[0])


@contextlib.contextmanager
def deferred():
    """Within the block, SIGINT and SIGTERM only take effect at :func:`check_interrupted`."""
    _deferring[0] = True
    try:
        yield
    finally:
        _deferring[0] = False


@contextlib.contextmanager
def interruptible():
    """Within the block, SIGINT and SIGTERM raise :class:`Interrupted` (main thread only);
    the previous handlers are restored afterwards."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _received.clear()
    previous = {sig: signal.signal(sig, _raise_interrupted)
                for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        _received.clear()


@contextlib.contextmanager
def warning_lines():
    """Warnings raised within the block (computed weights, skipped joints, heat's fallback)
    are collected and printed when it ends, each as one line ``rigedit: warning: ...`` on
    stderr: worth a line, not a traceback. Not printed when the block raises."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield
    if _quiet[0]:
        return
    for w in caught:
        print(f"rigedit: warning: {w.message}", file=sys.stderr)


def warn(message):
    """Print ``rigedit: warning: message`` on stderr, unless quiet (``-q``)."""
    if not _quiet[0]:
        print(f"rigedit: warning: {message}", file=sys.stderr)


@contextlib.contextmanager
def quiet_warnings():
    """Within the block, :func:`warning_lines` prints nothing (``-q``: errors only)."""
    _quiet[0] = True
    try:
        yield
    finally:
        _quiet[0] = False


def check_output(path, folder_ok=False):
    """``RigFileError`` naming ``path`` unless it can be written: its folder exists, and it is
    not an existing folder (unless ``folder_ok``: an output that is itself a folder)."""
    path = Path(path)
    check_output_folder(path)
    if path.is_dir() and not folder_ok:
        raise RigFileError(path, "expected a file name to write, got a folder")
