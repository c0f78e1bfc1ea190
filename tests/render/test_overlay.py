"""The overlay layer is made once per plotter and found again through VTK, with nothing set
on the plotter."""
import pyvista as pv

from rigedit.render.overlay import OVERLAY_LAYER, find_overlay, overlay_renderer


def test_the_overlay_is_made_once_and_found_again_without_a_foreign_attribute():
    plotter = pv.Plotter(off_screen=True)
    try:
        before = set(vars(plotter))
        count = plotter.render_window.GetRenderers().GetNumberOfItems()
        assert find_overlay(plotter) is None
        ren = overlay_renderer(plotter)
        assert ren.GetLayer() == OVERLAY_LAYER and not ren.GetInteractive()
        assert ren.GetActiveCamera() is plotter.renderer.GetActiveCamera()
        assert overlay_renderer(plotter) is ren and find_overlay(plotter) is ren
        assert plotter.render_window.GetRenderers().GetNumberOfItems() == count + 1
        assert set(vars(plotter)) == before
        other = pv.Plotter(off_screen=True)
        try:
            assert find_overlay(other) is None and overlay_renderer(other) is not ren
        finally:
            other.close()
    finally:
        plotter.close()
