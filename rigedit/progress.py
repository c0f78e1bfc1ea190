"""The one progress protocol every long job uses, and the one way to stop it.

A long job (heat weights, an embedding, an auto-rig, a retarget, a recording, a batch task)
takes an optional ``progress`` callable and calls it as ``progress(fraction, stage)``:

- ``fraction``: float in [0, 1], how much of the job is done, never decreasing; ``None`` when
  the job cannot tell (an indeterminate step);
- ``stage``: a short label of the step running (``"heat"``, ``"embed"``), or None.

To stop a job, the callable raises :class:`Cancelled`; the job lets it through after cleaning
up (temporary files removed, nothing half written), and whoever started it catches it. The
editor's Cancel button, the command line's Ctrl-C and a batch worker's shutdown all end a
job this way. Pure Python: no Qt.
"""
from __future__ import annotations

__all__ = ["Cancelled", "null_progress", "scaled", "report"]


class Cancelled(Exception):
    """Raised by a progress callable (or by a job at a step boundary) to stop a job."""


def null_progress(fraction, stage=None):
    """A progress callable that ignores what it is told."""


def scaled(progress, start, end, stage=None):
    """A progress callable that maps [0, 1] onto [start, end] of ``progress``.

    Used by a job made of steps: each step reports its own 0..1 and the caller sees one
    rising fraction. ``stage`` (when given) replaces the step's own label.

    Parameters
    ----------
    progress : callable or None
        The caller's progress callable; None gives :func:`null_progress`.
    start, end : float
        The part of the whole job this step covers, 0 <= start <= end <= 1.
    """
    if progress is None:
        return null_progress

    def step(fraction, label=None):
        value = None if fraction is None else start + (end - start) * min(max(fraction, 0.0), 1.0)
        progress(value, stage if stage is not None else label)

    return step


def report(progress, fraction, stage=None):
    """Call ``progress`` when there is one (a job's shorthand for the optional argument)."""
    if progress is not None:
        progress(fraction, stage)
