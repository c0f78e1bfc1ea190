"""The one place that reads a private attribute of pyvistaqt: whether its widget is painting.

Why it is needed: VTK asks for a render by itself (a sphere widget after each mouse move, the
camera style), and each such request rendered at once; the widget's Qt paint then rendered
again, so a drag move cost two renders and the drag rate halved (commit cacf901,
``benchmarks/bench_drag.py``; docs/performance.md, Dragging). :func:`route_renders_through_qt`
turns VTK's requests into one Qt paint, and it must tell the request made by the paint itself
(render now) from the others (schedule a paint). pyvistaqt's ``QVTKRenderWindowInteractor``
keeps that in ``_in_paint`` (the C++ widget's ``InPaint``) and offers no public way to read it.

At import this module checks that pyvistaqt still sets the attribute; when a release drops it
the redirect is not installed (:data:`HAS_IN_PAINT` is False, :func:`in_paint` says "not
painting") and VTK renders each request itself again: correct, only slower.
"""
from __future__ import annotations

import inspect

from pyvistaqt import QtInteractor

__all__ = ["HAS_IN_PAINT", "in_paint", "route_renders_through_qt"]

_ATTRIBUTE = "_in_paint"


def _sets_attribute(cls, name):
    """Whether a class of ``cls``'s MRO assigns ``self.<name>`` in its source (an instance
    attribute, so the class itself does not have it before an instance exists)."""
    for klass in cls.__mro__:
        try:
            source = inspect.getsource(klass)
        except (OSError, TypeError):   # a compiled (sip) class has no Python source
            continue
        if f"self.{name} =" in source:
            return True
    return False


#: Whether pyvistaqt's ``QtInteractor`` still keeps ``_in_paint`` (checked once, at import).
HAS_IN_PAINT = _sets_attribute(QtInteractor, _ATTRIBUTE)


def in_paint(plotter):
    """Whether ``plotter`` (a ``pyvistaqt.QtInteractor``) is inside its ``paintGL`` now;
    False when pyvistaqt no longer says (see the module's docstring)."""
    return HAS_IN_PAINT and bool(getattr(plotter, _ATTRIBUTE, False))


def route_renders_through_qt(plotter, on_error):
    """Make VTK's own render requests schedule one Qt paint instead of rendering now.

    ``vtkRenderWindowInteractor.Render`` always fires ``RenderEvent``, even with rendering
    disabled, so that such a redirect is possible. Without :data:`HAS_IN_PAINT` nothing is
    changed (VTK renders each request itself).

    Parameters
    ----------
    plotter : pyvistaqt.QtInteractor
    on_error : callable
        Called inside the ``except`` of a failed render (VTK would print and swallow it).

    Returns
    -------
    bool
        Whether the redirect was installed.
    """
    if not HAS_IN_PAINT:
        return False
    iren = plotter.iren.interactor
    rw = plotter.render_window
    iren.EnableRenderOff()

    def on_render_request(_obj, _event):
        try:
            if in_paint(plotter):  # inside paintGL: render for real
                rw.Render()
            else:
                plotter.update()
        except Exception:  # noqa: BLE001 - VTK would print and swallow it
            on_error()

    iren.AddObserver("RenderEvent", on_render_request)
    return True
