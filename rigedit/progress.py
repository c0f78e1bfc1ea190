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

import inspect
import warnings

__all__ = ["Cancelled", "null_progress", "scaled", "report", "adapt", "takes_stage"]


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

    fixed = stage

    def step(fraction, stage=None):
        value = None if fraction is None else start + (end - start) * min(max(fraction, 0.0), 1.0)
        progress(value, fixed if fixed is not None else stage)

    return step


def report(progress, fraction, stage=None):
    """Call ``progress`` when there is one (a job's shorthand for the optional argument)."""
    if progress is not None:
        progress(fraction, stage)


def takes_stage(progress):
    """True when ``progress`` can be called as ``progress(fraction, stage)``.

    A callable whose signature Python cannot read (some builtins) is taken to follow the
    protocol.
    """
    try:
        signature = inspect.signature(progress)
    except (TypeError, ValueError):
        return True
    try:
        signature.bind(0.0, None)
    except TypeError:
        return False
    return True


def adapt(progress, stage=None):
    """``progress`` as a callable of this protocol, for a job to call as ``p(fraction, stage)``.

    Kept while older callers move over: a callable that takes the fraction alone (the
    ``progress(fraction)`` that heat, the embedding and the inverse-distance weights took
    before this protocol) still works, wrapped to drop the stage, with a
    ``DeprecationWarning``. A cancel it raises goes through as before.

    Parameters
    ----------
    progress : callable or None
        ``progress(fraction, stage)``, or the deprecated ``progress(fraction)``.
    stage : str, optional
        A label for calls that give none (the job's name).

    Returns
    -------
    callable(fraction, stage=None)
        :func:`null_progress` when ``progress`` is None.
    """
    if progress is None:
        return null_progress
    if not takes_stage(progress):
        warnings.warn("a progress callable of one argument, progress(fraction), is deprecated: "
                      "take progress(fraction, stage) (rigedit.progress)", DeprecationWarning,
                      stacklevel=3)
        one = progress

        def progress(fraction, stage=None):
            one(fraction)
    if stage is None:
        return progress
    call, default = progress, stage

    def labelled(fraction, stage=None):
        call(fraction, default if stage is None else stage)

    return labelled
