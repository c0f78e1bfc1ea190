"""Long work off the UI thread: a QThread running a pure function with progress and cancel.

The function never touches Qt widgets or VTK; it reports progress through ``report(fraction)``,
which raises :class:`Cancelled` once the user pressed Cancel. Results come back on the main
thread through Qt signals, where the caller applies them (VTK calls stay on the main thread).
"""
from __future__ import annotations

import threading

from PyQt5 import QtCore

from ..model.weights import compute_weights

__all__ = ["Cancelled", "Job", "weights_in_chunks"]


class Cancelled(Exception):
    """The user cancelled the job."""


class Job(QtCore.QThread):
    """Run ``fn(report)`` in a thread.

    Signals
    -------
    progress(int)      percent done, 0-100 (-1 when the job cannot tell)
    succeeded(object)  the function's result
    failed(str)        one-line error message (ValueError and RigFileError keep their text)
    cancelled()
    """

    progress = QtCore.pyqtSignal(int)
    succeeded = QtCore.pyqtSignal(object)
    failed = QtCore.pyqtSignal(str)
    cancelled = QtCore.pyqtSignal()

    def __init__(self, label, fn, parent=None):
        super().__init__(parent)
        self.label = label
        self.fn = fn
        self._cancel = threading.Event()

    def cancel(self):
        self._cancel.set()

    @property
    def is_cancelled(self):
        return self._cancel.is_set()

    def report(self, fraction):
        if self._cancel.is_set():
            raise Cancelled()
        self.progress.emit(-1 if fraction is None else int(round(100 * fraction)))

    def run(self):
        try:
            result = self.fn(self.report)
            if self._cancel.is_set():
                raise Cancelled()
        except Cancelled:
            self.cancelled.emit()
        except (ValueError, KeyError, OSError) as exc:
            self.failed.emit(str(exc).strip("'\""))
        except Exception as exc:  # noqa: BLE001 - shown to the user, never a silent thread death
            from .errors_hook import describe, logger

            summary = describe(type(exc), exc, exc.__traceback__)
            logger().error("%s failed: %s", self.label, summary, exc_info=True)
            self.failed.emit(f"unexpected {summary}; details in the log")
        else:
            self.succeeded.emit(result)


def weights_in_chunks(vertices, skeleton, method="idw", report=None):
    """Compute skin weights with progress: ``report(fraction)`` is called after each block
    of vertices, and its :class:`Cancelled` stops the work between blocks.

    Returns
    -------
    indices : (V, K) int32
    weights : (V, K) float64
    """
    return compute_weights(vertices, skeleton, method, progress=report)
