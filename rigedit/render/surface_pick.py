"""Points on a shown mesh under the mouse: the mouse ray against the skinned surface.

:class:`SurfacePicker` finds where the ray through a display pixel first crosses a mesh,
with a VTK cell locator rebuilt only when the mesh's points moved; :func:`world_radius`
turns a radius in screen pixels into scene units at a point's depth; :func:`nearest_vertex`
finds the vertex nearest a point. Used by the weight brush (:mod:`rigedit.ui.weight_brush`).
Never imports Qt.
"""
from __future__ import annotations

import numpy as np
from vtkmodules.vtkCommonCore import reference
from vtkmodules.vtkCommonDataModel import vtkStaticCellLocator

from .ray import display_to_world, world_to_display

__all__ = ["SurfacePicker", "world_radius", "nearest_vertex"]


class SurfacePicker:
    """The point of a mesh under a display pixel, through a cached cell locator."""

    def __init__(self):
        self._locator = None
        self._locator_stamp = None

    def reset(self):
        """Forget the locator (a new rig: the next pick builds one)."""
        self._locator_stamp = None

    def pick(self, renderer, mesh, x, y):
        """The point of ``mesh`` (pyvista.PolyData, as shown) under display pixel (x, y) of
        ``renderer``, or None: the first crossing of the mouse ray with the surface, found
        with a cell locator (a vtkCellPicker tested every triangle: 44 ms a pick on the
        60k-triangle quadruped, measured).

        Returns
        -------
        point : (3,) float64 or None
        """
        if not renderer.IsInViewport(int(x), int(y)):
            return None
        locator = self._current_locator(mesh)
        if locator is None:
            return None
        ends = [display_to_world(renderer, x, y, z) for z in (0.0, 1.0)]
        t, sub, cell = reference(0.0), reference(0), reference(0)
        hit, pcoords = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
        if not locator.IntersectWithLine(ends[0], ends[1], 0.0, t, hit, pcoords, sub, cell):
            return None
        return np.array(hit)

    def _current_locator(self, mesh):
        """The cell locator of ``mesh``, rebuilt when its points moved (a new pose; about
        16 ms on the quadruped), not when only its colours changed."""
        if mesh.n_cells == 0:
            return None
        stamp = (id(mesh), mesh.GetPoints().GetMTime())
        if self._locator_stamp != stamp:
            self._locator = vtkStaticCellLocator()
            self._locator.SetDataSet(mesh)
            self._locator.BuildLocator()
            self._locator_stamp = stamp
        return self._locator


def world_radius(renderer, point, pixels):
    """Scene units that ``pixels`` span on screen at the depth of ``point`` (3,)."""
    dx, dy, dz = world_to_display(renderer, point)
    return float(np.linalg.norm(display_to_world(renderer, dx + float(pixels), dy, dz) - point))


def nearest_vertex(points, point):
    """Index of the row of ``points`` (N, 3) nearest ``point`` (3,)."""
    pts = np.asarray(points)
    return int(np.argmin(np.einsum("ij,ij->i", pts - point, pts - point)))
