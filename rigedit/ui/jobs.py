"""Long work off the UI thread: a QThread running a pure function with progress and cancel.

The function never touches Qt widgets or VTK; it reports progress through ``report(fraction)``,
which raises :class:`Cancelled` once the user pressed Cancel. Results come back on the main
thread through Qt signals, where the caller applies them (VTK calls stay on the main thread).
"""
from __future__ import annotations

import threading

from PyQt5 import QtCore

from ..binding.weights import compute_weights, default_method

__all__ = ["Cancelled", "Job", "JobsMixin", "weights_in_chunks"]


class Cancelled(Exception):
    """The user cancelled the job."""


class Job(QtCore.QThread):
    """Run ``fn(report)`` in a thread.

    Signals
    -------
    progress(int)      percent done, 0-100 (-1 when the job cannot tell)
    succeeded(object)  the function's result
    failed(str)        one-line error message (ValueError and RigFileError keep their text);
                       ``unexpected`` is then true when it was a bug, not bad input
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
        self.unexpected = False

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
            self.unexpected = True
            self.failed.emit(summary)
        else:
            self.succeeded.emit(result)


class JobsMixin:
    """:meth:`run_job` and :meth:`cancel_job` of :class:`~rigedit.ui.main_window.MainWindow`
    (which has ``job``, ``progress``, ``cancel_button``, ``status``, ``error``,
    ``report_exception`` and ``_update_undo_actions``)."""

    def run_job(self, label, fn, on_done, on_cancel=None):
        """Run ``fn(report)`` off the UI thread with a progress bar and a Cancel button;
        ``on_done(result)`` runs on the main thread. Returns the :class:`Job`."""
        if self.job is not None:
            self.error("Busy", f"busy with '{self.job.label}': wait for it to finish, or "
                               f"cancel it, then try '{label}' again")
            return None
        job = Job(label, fn, self)
        self.job = job
        self.progress.setRange(0, 100)
        self.progress.setValue(0)
        self.progress.setFormat(f"{label}: %p%")
        self.progress.setVisible(True)
        self.cancel_button.setVisible(True)

        def progress(p):
            if p < 0:
                self.progress.setRange(0, 0)
            else:
                self.progress.setRange(0, 100)
                self.progress.setValue(p)

        def finish():
            self.job = None
            self.progress.setVisible(False)
            self.cancel_button.setVisible(False)
            self._update_undo_actions()

        def ok(result):
            finish()
            try:
                on_done(result)
            except ValueError as exc:
                self.error(label, str(exc))
            except Exception:  # noqa: BLE001 - a bug: shown and logged, the editor goes on
                self.report_exception(label)

        def failed(msg):
            finish()
            if on_cancel:
                on_cancel()
            # after on_cancel, so that its status does not hide the error
            if job.unexpected:  # a bug: logged by the job, shown as one
                self.show_unexpected_error(label, msg)
            else:
                self.error(label, msg)

        def cancelled():
            finish()
            self.status(f"{label}: cancelled")
            if on_cancel:
                on_cancel()

        job.progress.connect(progress)
        job.succeeded.connect(ok)
        job.failed.connect(failed)
        job.cancelled.connect(cancelled)
        job.finished.connect(job.deleteLater)
        self.status(f"{label}...")
        job.start()
        self._update_undo_actions()
        return job

    def cancel_job(self):
        if self.job is not None:
            self.job.cancel()


def weights_in_chunks(vertices, skeleton, method=None, report=None, faces=None):
    """Compute skin weights with progress: ``report(fraction)`` is called after each block
    of vertices, and its :class:`Cancelled` stops the work between blocks.

    Returns
    -------
    indices : (V, K) int32
    weights : (V, K) float64
    """
    method = method or default_method(faces)  # heat for a mesh, idw for a point cloud
    return compute_weights(vertices, skeleton, method, progress=report, faces=faces)
