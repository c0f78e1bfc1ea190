"""Mouse observers on a VTK interactor whose exceptions are never lost.

VTK prints and swallows an exception raised in an observer. These helpers keep its traceback
in the owner's ``errors`` list and hand it to the owner's ``on_error(what)`` handler (the
editor shows and logs it), or, without one, re-emit it as a warning so that tests run with
warnings as errors fail.
"""
from __future__ import annotations

import traceback
import warnings

__all__ = ["record_failure", "add_mouse_observers", "remove_observers"]


def record_failure(owner, what):
    """Keep the traceback of a failed VTK callback in ``owner.errors``, then hand the
    exception (still being handled) to ``owner.on_error(what)``, or warn with it."""
    tb = traceback.format_exc()
    owner.errors.append(tb)
    handler = owner.on_error
    if handler is None:
        warnings.warn(f"{what} callback failed:\n{tb}", RuntimeWarning, stacklevel=2)
    else:
        handler(f"The {what} callback")


def add_mouse_observers(iren, handlers, priority, owner, what):
    """Observe interactor events at ``priority``; a handler returning True takes the event
    (observers of lower priority, such as the camera style at 0, never see it).

    Parameters
    ----------
    iren : vtkRenderWindowInteractor
    handlers : dict
        Event name ("LeftButtonPressEvent", ...) -> ``fn(iren)`` returning bool.
    priority : float
    owner : object
        Has ``errors`` (list) and ``on_error`` (see :func:`record_failure`).
    what : str
        Names the owner in error messages ("joint gizmo").

    Returns
    -------
    tags : list of int
        Observer tags, for :func:`remove_observers`.
    """
    tags = {}

    def guard(fn):
        def callback(obj, event):
            try:
                if fn(obj):
                    obj.GetCommand(tags[event]).SetAbortFlag(1)
            except Exception:  # noqa: BLE001 - VTK would swallow it; keep it visible
                record_failure(owner, what)
        return callback

    for event, fn in handlers.items():
        tags[event] = iren.AddObserver(event, guard(fn), priority)
    return list(tags.values())


def remove_observers(iren, tags):
    if iren is not None:
        for tag in tags:
            iren.RemoveObserver(tag)
