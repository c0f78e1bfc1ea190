"""All joint spheres as one actor of sphere imposters, coloured per joint by state.

``vtkOpenGLSphereMapper`` draws each joint as one screen-facing square whose fragment shader
shades and depth-tests the exact sphere (normal and depth from the ray-sphere hit), so the
forty spheres are 80 triangles, round at any size. Forty ``vtkSphereWidget`` s drew forty
actors of 320 triangles each; a ``vtkGlyph3DMapper`` of 144-triangle spheres after them still
cost 1.4 ms of a 19 ms frame in software OpenGL, where triangles are set up one by one, and
the imposters about half of that (README, Speed). Each joint's colour is a direct RGB scalar
on the input points, so changing a selection or a hover highlight rewrites a few bytes instead
of swapping properties. Never imports Qt.
"""
from __future__ import annotations

import numpy as np
import pyvista as pv
from vtkmodules.vtkRenderingCore import vtkActor
from vtkmodules.vtkRenderingOpenGL2 import vtkOpenGLSphereMapper

__all__ = ["JointGlyphs", "SPHERE_COLOR", "SELECTED_COLOR", "ACTIVE_COLOR",
           "NON_DEFORMING_COLOR", "CARRIER_COLOR", "hover_color"]

SPHERE_COLOR = (0.55, 0.78, 1.0)
NON_DEFORMING_COLOR = (0.60, 0.65, 0.74)  # takes no skin weight
#: A carrier root (a joint on the floor or at the origin that only moves the figure): a dim
#: mid grey, darker than the other spheres, so it does not read as a joint of the body
CARRIER_COLOR = (0.50, 0.53, 0.58)
SELECTED_COLOR = (1.0, 0.62, 0.10)
ACTIVE_COLOR = (1.0, 0.95, 0.35)  # while being dragged


def hover_color(color):
    """The hover highlight of ``color``: half way to white."""
    c = np.asarray(color, dtype=float)
    return tuple(c + 0.5 * (1.0 - c))


def _rgb(color):
    return np.round(np.asarray(color, dtype=float) * 255).astype(np.uint8)


class JointGlyphs:
    """Spheres of one radius at joint positions, drawn as one actor.

    Parameters
    ----------
    positions : (J, 3) float
    radius : float
        Sphere radius (model units).
    deform : (J,) bool, optional
        Joints that take skin weight; the others are drawn in ``NON_DEFORMING_COLOR``.
    carriers : (J,) bool, optional
        Carrier roots, drawn in ``CARRIER_COLOR`` (see :mod:`rigedit.model.carrier`).

    Attributes
    ----------
    actor : vtkActor
        Add it to a renderer.
    points : pyvista.PolyData
        The glyphs' centres (its ``points`` are the joint positions).
    selected, hovered, active : int or None
        Joints drawn highlighted (in that order of precedence, ``active`` first).
    """

    def __init__(self, positions, radius, deform=None, carriers=None):
        positions = np.asarray(positions, dtype=float).reshape(-1, 3)
        self.radius = float(radius)
        self.points = pv.PolyData(positions.copy())
        self._xyz = self.points.points  # a view of VTK's array, kept: the wrapper costs 50 us
        n = len(positions)
        self.deform = np.ones(n, dtype=bool) if deform is None else \
            np.asarray(deform, dtype=bool).reshape(n)
        self.carriers = np.zeros(n, dtype=bool) if carriers is None else \
            np.asarray(carriers, dtype=bool).reshape(n)
        self.selected = self.hovered = self.active = None
        self._colors = np.zeros((n, 3), dtype=np.uint8)
        self.points.point_data["rgb"] = self._colors
        # pyvista copies on assignment: write through VTK's own array from now on
        self._colors = self.points.point_data["rgb"]
        mapper = vtkOpenGLSphereMapper()
        mapper.SetInputData(self.points)
        mapper.SetRadius(self.radius)
        mapper.SetScalarModeToUsePointFieldData()
        mapper.SelectColorArray("rgb")
        mapper.SetColorModeToDirectScalars()
        mapper.ScalarVisibilityOn()
        self.mapper = mapper
        self.actor = vtkActor()
        self.actor.SetMapper(mapper)
        self.actor.PickableOff()  # picked by rigedit's own ray maths, not VTK pickers
        prop = self.actor.GetProperty()
        prop.SetSpecular(0.4)
        # A widget's SetColor tinted its highlight too; one colour for all glyphs keeps the
        # spheres' look (an untinted white highlight made them visibly paler).
        prop.SetSpecularColor(SPHERE_COLOR)
        self._recolor()

    def __len__(self):
        return len(self._xyz)

    # ------------------------------------------------------------------ positions
    @property
    def positions(self):
        """(J, 3) float64 view of the sphere centres (write through :meth:`set_positions`)."""
        return self._xyz

    def set_positions(self, positions, skip=None):
        """Move every sphere (but ``skip``) onto ``positions`` (J, 3)."""
        pts = self._xyz
        if skip is None:
            pts[:] = positions
        else:
            keep = pts[skip].copy()
            pts[:] = positions
            pts[skip] = keep
        self._points_changed()

    def set_center(self, j, p):
        self._xyz[j] = p
        self._points_changed()

    def _points_changed(self):
        self.points.GetPoints().Modified()
        self.points.Modified()

    # ------------------------------------------------------------------ colours
    def color_of(self, j):
        """(3,) float RGB in [0, 1] that joint ``j`` is drawn in now."""
        return self._colors[j] / 255.0

    def set_state(self, selected=..., hovered=..., active=...):
        """Change the highlighted joints (an argument left out keeps its value)."""
        if selected is not ...:
            self.selected = selected
        if hovered is not ...:
            self.hovered = hovered
        if active is not ...:
            self.active = active
        self._recolor()

    def set_deform(self, deform):
        self.deform = np.asarray(deform, dtype=bool).reshape(len(self))
        self._recolor()

    def _recolor(self):
        colors = np.where(self.deform[:, None], _rgb(SPHERE_COLOR), _rgb(NON_DEFORMING_COLOR))
        colors[self.carriers] = _rgb(CARRIER_COLOR)
        if self.selected is not None:
            colors[self.selected] = _rgb(SELECTED_COLOR)
        if self.hovered is not None:
            colors[self.hovered] = _rgb(hover_color(colors[self.hovered] / 255.0))
        if self.active is not None:
            colors[self.active] = _rgb(ACTIVE_COLOR)
        self._colors[:] = colors
        self.points.GetPointData().GetArray("rgb").Modified()
        self.points.Modified()

    # ------------------------------------------------------------------ visibility
    def set_visible(self, visible):
        self.actor.SetVisibility(bool(visible))

    @property
    def visible(self):
        return bool(self.actor.GetVisibility())
