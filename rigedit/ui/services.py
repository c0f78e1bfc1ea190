"""What the window lends its parts: the few services each part uses, given in its constructor
instead of the whole window."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

__all__ = ["Services"]


@dataclass(frozen=True)
class Services:
    """The window's services.

    Attributes
    ----------
    parent : QWidget
        The parent of the parts' dialogs and actions (the window).
    status : callable
        ``status(text, timeout=0)``: the status line.
    error : callable
        ``error(title, message)``: one clear message for bad input (a dialog and the
        status line).
    report_exception : callable
        ``report_exception(what)`` inside an ``except``: logs and shows a bug (for code that
        must not let it propagate: VTK observers, job callbacks).
    request_render : callable
        ``request_render()``: one repaint of the 3D view.
    jobs : JobRunner
        Runs work off the UI thread with the progress bar and Cancel (one job at a time).
    """

    parent: object
    status: Callable
    error: Callable
    report_exception: Callable
    request_render: Callable
    jobs: object

    def run_job(self, label, fn, on_done, on_cancel=None, show_stage=False):
        """:meth:`JobRunner.run <rigedit.ui.jobs.JobRunner.run>`."""
        return self.jobs.run(label, fn, on_done, on_cancel, show_stage)
