"""Long work off the UI thread: a QThread running a pure function with progress and cancel.

The function never touches Qt widgets or VTK; it reports progress through
``report(fraction, stage=None)`` (:mod:`rigedit.progress`'s protocol), which raises
:class:`~rigedit.progress.Cancelled` once the user pressed Cancel. Results come back on the main
thread through Qt signals, where the caller applies them (VTK calls stay on the main thread).
"""
from __future__ import annotations

import threading

from PyQt5 import QtCore, QtWidgets

from ..progress import Cancelled  # the one way to stop a job (rigedit.progress)

__all__ = ["Cancelled", "Job", "JobRunner"]


class Job(QtCore.QThread):
    """Run ``fn(report)`` in a thread.

    Signals
    -------
    progress(int)      percent done, 0-100 (-1 when the job cannot tell)
    stage(str)         the name of the step now running, when it changes
    succeeded(object)  the function's result
    failed(str)        one-line error message (ValueError and RigFileError keep their text);
                       ``unexpected`` is then true when it was a bug, not bad input
    cancelled()
    """

    progress = QtCore.pyqtSignal(int)
    stage = QtCore.pyqtSignal(str)
    succeeded = QtCore.pyqtSignal(object)
    failed = QtCore.pyqtSignal(str)
    cancelled = QtCore.pyqtSignal()

    def __init__(self, label, fn, parent=None):
        super().__init__(parent)
        self.label = label
        self.fn = fn
        self._cancel = threading.Event()
        self._stage = None
        self.unexpected = False

    def cancel(self):
        self._cancel.set()

    @property
    def is_cancelled(self):
        return self._cancel.is_set()

    def report(self, fraction, stage=None):
        """The job's progress callable: ``fraction`` done (None: cannot tell) in step
        ``stage``; raises :class:`Cancelled` after :meth:`cancel`."""
        if self._cancel.is_set():
            raise Cancelled()
        self.progress.emit(-1 if fraction is None else int(round(100 * fraction)))
        if stage and stage != self._stage:
            self._stage = stage
            self.stage.emit(str(stage))

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


class JobRunner(QtCore.QObject):
    """Runs one :class:`Job` at a time with the status bar's progress bar and Cancel button.

    Parameters
    ----------
    status_bar : QStatusBar
        Gets the progress bar and the Cancel button (hidden while no job runs).
    status : callable
        ``status(text)``.
    error : callable
        ``error(title, message)`` for bad input (a ``ValueError``, a file that cannot be read).
    unexpected_error : callable
        ``unexpected_error(what, summary)`` for a bug in the job.
    report_exception : callable
        ``report_exception(what)`` inside the ``except`` of a failed ``on_done``.

    Attributes
    ----------
    job : Job or None
        The job running now.
    progress : QProgressBar
    cancel_button : QPushButton
    changed : pyqtSignal()
        A job started or ended (what Undo would do may have changed).
    """

    changed = QtCore.pyqtSignal()

    def __init__(self, status_bar, status, error, unexpected_error, report_exception):
        super().__init__(status_bar)
        self.status = status
        self.error = error
        self.unexpected_error = unexpected_error
        self.report_exception = report_exception
        self.job = None
        self.progress = QtWidgets.QProgressBar()
        self.progress.setMaximumWidth(220)
        self.progress.setVisible(False)
        self.cancel_button = QtWidgets.QPushButton("Cancel")
        self.cancel_button.setVisible(False)
        self.cancel_button.clicked.connect(self.cancel)
        status_bar.addPermanentWidget(self.progress)
        status_bar.addPermanentWidget(self.cancel_button)

    def current(self):
        """The job running now, or None."""
        return self.job

    def run(self, label, fn, on_done, on_cancel=None, show_stage=False):
        """Run ``fn(report)`` off the UI thread with a progress bar and a Cancel button;
        ``on_done(result)`` runs on the main thread (``on_cancel()`` after a cancel or a
        failure). With ``show_stage`` the bar names the step ``report`` was last given.
        Returns the :class:`Job`, or None (with a message) when another job runs."""
        if self.job is not None:
            self.error("Busy", f"busy with '{self.job.label}': wait for it to finish, or "
                               f"cancel it, then try '{label}' again")
            return None
        job = Job(label, fn, self)
        self.job = job
        self._show(label)
        job.progress.connect(self._progress)
        if show_stage:
            job.stage.connect(lambda stage: self._show_stage(job, stage))
        job.succeeded.connect(lambda result: self._succeeded(job, on_done, result))
        job.failed.connect(lambda msg: self._failed(job, on_cancel, msg))
        job.cancelled.connect(lambda: self._cancelled(job, on_cancel))
        job.finished.connect(job.deleteLater)
        self.status(f"{label}...")
        job.start()
        self.changed.emit()
        return job

    def cancel(self):
        if self.job is not None:
            self.job.cancel()

    # ------------------------------------------------------------------ the bar
    def _show(self, label):
        self.progress.setRange(0, 100)
        self.progress.setValue(0)
        self.progress.setFormat(f"{label}: %p%")
        self.progress.setVisible(True)
        self.cancel_button.setVisible(True)

    def _show_stage(self, job, stage):
        if job is self.job:
            self.progress.setFormat(f"{job.label}: {stage} %p%")

    def _progress(self, p):
        if p < 0:
            self.progress.setRange(0, 0)   # the job cannot tell: a busy bar
        else:
            self.progress.setRange(0, 100)
            self.progress.setValue(p)

    def _finish(self):
        self.job = None
        self.progress.setVisible(False)
        self.cancel_button.setVisible(False)
        self.changed.emit()

    # ------------------------------------------------------------------ the outcome
    def _succeeded(self, job, on_done, result):
        self._finish()
        try:
            on_done(result)
        except ValueError as exc:
            self.error(job.label, str(exc))
        except Exception:  # noqa: BLE001 - a bug: shown and logged, the editor goes on
            self.report_exception(job.label)

    def _failed(self, job, on_cancel, msg):
        self._finish()
        if on_cancel:
            on_cancel()
        # after on_cancel, so that its status does not hide the error
        if job.unexpected:  # a bug: logged by the job, shown as one
            self.unexpected_error(job.label, msg)
        else:
            self.error(job.label, msg)

    def _cancelled(self, job, on_cancel):
        self._finish()
        self.status(f"{job.label}: cancelled")
        if on_cancel:
            on_cancel()

