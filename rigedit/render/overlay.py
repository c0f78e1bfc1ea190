"""The overlay renderer: a second layer drawn over the mesh, for bones and gizmos."""
from __future__ import annotations

from vtkmodules.vtkRenderingCore import vtkRenderer

__all__ = ["overlay_renderer", "find_overlay", "OVERLAY_LAYER"]

#: The render window layer of the overlay (the plotter's own renderer is layer 0).
OVERLAY_LAYER = 1


def find_overlay(plotter):
    """The overlay :func:`overlay_renderer` added to ``plotter``'s render window, or None.

    Found through VTK's public API, among the window's renderers: the one on
    ``OVERLAY_LAYER`` that takes no interaction and shares the plotter's camera. The render
    window owns its renderers, so no attribute is set on the plotter (a foreign object) and
    no table of plotters is kept here.
    """
    camera = plotter.renderer.GetActiveCamera()
    renderers = plotter.render_window.GetRenderers()
    renderers.InitTraversal()
    for _ in range(renderers.GetNumberOfItems()):
        ren = renderers.GetNextItem()
        if (ren.GetLayer() == OVERLAY_LAYER and not ren.GetInteractive()
                and ren.GetActiveCamera() is camera):
            return ren
    return None


def overlay_renderer(plotter):
    """A renderer drawn over the plotter's own, sharing its camera, so bones and joint
    gizmos stay visible inside an opaque mesh (what "in front" does in other 3D tools).

    Created once per plotter (a later call returns it, see :func:`find_overlay`); its depth
    buffer is cleared, so its actors hide each other correctly but never hide behind the
    mesh. It does not take camera interaction.

    Parameters
    ----------
    plotter : pyvista.Plotter or pyvistaqt.QtInteractor

    Returns
    -------
    vtkRenderer
    """
    existing = find_overlay(plotter)
    if existing is not None:
        return existing
    ren_win = plotter.render_window
    ren = vtkRenderer()
    ren.SetLayer(OVERLAY_LAYER)
    ren.InteractiveOff()
    ren.SetActiveCamera(plotter.renderer.GetActiveCamera())
    ren.SetViewport(plotter.renderer.GetViewport())
    ren_win.SetNumberOfLayers(max(2, ren_win.GetNumberOfLayers()))
    ren_win.AddRenderer(ren)
    return ren
