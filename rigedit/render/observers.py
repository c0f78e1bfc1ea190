"""Mouse observers on a VTK interactor whose exceptions are never lost, and the left-button
drag that the joint spheres and the axis arrows share (:class:`LeftButtonDrag`).

VTK prints and swallows an exception raised in an observer. These helpers keep its traceback
in the owner's ``errors`` list and hand it to the owner's ``on_error(what)`` handler (the
editor shows and logs it), or, without one, re-emit it as a warning so that tests run with
warnings as errors fail.
"""
from __future__ import annotations

import traceback
import warnings

__all__ = ["record_failure", "add_mouse_observers", "remove_observers", "LeftButtonDrag"]


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


class LeftButtonDrag:
    """Left-button drags of a gizmo through interactor observers (a mixin).

    A press where ``pick(x, y)`` finds something starts ``start_drag(item, x, y)``; mouse
    moves go to ``drag_to_pixel(x, y)``; the release to ``end_drag()``. Each event the drag
    takes is aborted (the camera never sees it) and asks the interactor to render. A move
    with no drag goes to ``hover(iren, x, y)`` and on to the camera. The class holds
    ``_grab`` (None when no drag is under way; else a dict whose ``"item"`` is what was
    grabbed) and calls the owner's ``on_end(item)`` and ``_drag_ended()`` at the release.
    """

    _grab = None

    def end_drag(self):
        """End the drag: ``on_end(item)``, then ``_drag_ended()`` even if that raised."""
        grab, self._grab = self._grab, None
        if grab is None:
            return
        try:
            if self.on_end:
                self.on_end(grab["item"])
        finally:
            self._drag_ended()

    def _drag_ended(self):
        """Draw the gizmo as no longer grabbed (after :meth:`end_drag`)."""

    def observe(self, iren, priority, what):
        """Start listening to ``iren``; returns the observer tags."""
        return add_mouse_observers(
            iren, {"LeftButtonPressEvent": self._press, "MouseMoveEvent": self._mouse_move,
                   "LeftButtonReleaseEvent": self._release, "LeaveEvent": self._leave},
            priority, self, what)

    def hover(self, iren, x, y):
        """A mouse move with no drag, or the mouse leaving the view (``x``, ``y`` None);
        nothing by default."""

    def _leave(self, iren):
        self.hover(iren, None, None)
        return False

    def _press(self, iren):
        if self._grab is not None:
            return True
        x, y = iren.GetEventPosition()
        item = self.pick(x, y)
        if item is None:
            return False
        try:
            self.start_drag(item, x, y)
        finally:
            iren.Render()
        return True

    def _mouse_move(self, iren):
        x, y = iren.GetEventPosition()
        if self._grab is None:
            self.hover(iren, x, y)
            return False
        try:
            self.drag_to_pixel(x, y)
        finally:
            iren.Render()
        return True

    def _release(self, iren):
        if self._grab is None:
            return False
        try:
            self.end_drag()
        finally:
            iren.Render()
        return True
