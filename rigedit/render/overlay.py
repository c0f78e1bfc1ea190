"""The overlay renderer: a second layer drawn over the mesh, for bones and gizmos."""
from __future__ import annotations

from vtkmodules.vtkRenderingCore import vtkRenderer

__all__ = ["overlay_renderer"]


def overlay_renderer(plotter):
    """A renderer drawn over the plotter's own, sharing its camera, so bones and joint
    gizmos stay visible inside an opaque mesh (what "in front" does in other 3D tools).

    Created once per plotter; its depth buffer is cleared, so its actors hide each other
    correctly but never hide behind the mesh. It does not take camera interaction.
    """
    existing = getattr(plotter, "_rigedit_overlay", None)
    if existing is not None:
        return existing
    ren_win = plotter.render_window
    ren = vtkRenderer()
    ren.SetLayer(1)
    ren.InteractiveOff()
    ren.SetActiveCamera(plotter.renderer.GetActiveCamera())
    ren.SetViewport(plotter.renderer.GetViewport())
    ren_win.SetNumberOfLayers(max(2, ren_win.GetNumberOfLayers()))
    ren_win.AddRenderer(ren)
    plotter._rigedit_overlay = ren
    return ren
