"""A second, thin skeleton drawn over the rig: the compressed clip's pose, each joint coloured
by its error (View > Compare compressed).

Bones are one line actor, joints one actor of small sphere imposters
(:class:`~rigedit.render.joint_glyphs.JointGlyphs`, coloured here by error instead of state),
and a corner text gives the figures. They sit on a render layer of their own above the
editor's overlay (:data:`COMPARE_LAYER`): the compressed joints are within a fraction of a
millimetre of the original ones, inside the editor's joint spheres, which would hide them in
one depth buffer. :meth:`CompareOverlay.update` writes positions and colours into the actors'
arrays in place each frame. Never imports Qt.
"""
from __future__ import annotations

import numpy as np
import pyvista as pv
from vtkmodules.vtkRenderingAnnotation import vtkScalarBarActor
from vtkmodules.vtkRenderingCore import (vtkActor, vtkColorTransferFunction, vtkPolyDataMapper,
                                         vtkRenderer, vtkTextActor)

from .joint_glyphs import JointGlyphs
from .overlay import OVERLAY_LAYER

__all__ = ["CompareOverlay", "error_colors", "GREEN", "YELLOW", "RED", "LINE_COLOR",
           "COMPARE_LAYER"]

#: Above the editor's overlay (bones, joint spheres, handles)
COMPARE_LAYER = OVERLAY_LAYER + 1

GREEN = (0.20, 0.85, 0.30)
YELLOW = (1.00, 0.88, 0.15)
RED = (0.95, 0.15, 0.12)
#: The compressed skeleton's bones: pale, thin, so the coloured joints carry the meaning
LINE_COLOR = (0.92, 0.92, 0.92)
#: The joints' radius against the editor's joint spheres
RADIUS_FRACTION = 0.6


def error_colors(errors, bound):
    """RGB (J, 3) uint8 of errors: green at 0, yellow at half the bound, red at the bound
    (and above), linear in between.

    Parameters
    ----------
    errors : (J,) float
        Metres.
    bound : float
        Metres, > 0.
    """
    u = np.clip(np.asarray(errors, dtype=float) / float(bound), 0.0, 1.0)[:, None]
    low, high = np.asarray(GREEN), np.asarray(YELLOW)
    rgb = np.where(u <= 0.5, low + (high - low) * (2 * u), high + (np.asarray(RED) - high)
                   * (2 * u - 1))
    return np.round(rgb * 255).astype(np.uint8)


class _ErrorGlyphs(JointGlyphs):
    """Joint imposters whose colours are set from outside (:meth:`set_colors`)."""

    def __init__(self, positions, radius):
        self._fixed = np.zeros((len(positions), 3), dtype=np.uint8)
        super().__init__(positions, radius)

    def set_colors(self, rgb):
        self._fixed[:] = rgb
        self._recolor()

    def _recolor(self):
        self._colors[:] = self._fixed
        self.points.GetPointData().GetArray("rgb").Modified()
        self.points.Modified()


class CompareOverlay:
    """The compressed pose over the original, coloured by error.

    Parameters
    ----------
    plotter : pyvista.Plotter or pyvistaqt.QtInteractor
        Gets a renderer of its own on :data:`COMPARE_LAYER`, sharing the plotter's camera
        (:meth:`remove` takes it out again).
    positions : (J, 3) float
        The compressed pose's joint positions (model space).
    parents : (J,) int
        -1 for a root.
    errors : (J,) float
        Metres.
    bound : float
        Metres: the error drawn red.
    radius : float
        The joints' spheres' radius (model units).
    carriers : (J,) bool, optional
        Carrier roots (:func:`rigedit.render.camera.figure_joints`): no line from them to
        their children, as the editor's own bones.

    Attributes
    ----------
    renderer : vtkRenderer
    bones : pyvista.PolyData
        One point per joint, one line per bone.
    glyphs : JointGlyphs
    text : vtkTextActor
        The figures (lower left): :meth:`set_text`.
    legend : vtkScalarBarActor
        The colours against the error in centimetres, 0 to the bound (above the text).
    """

    def __init__(self, plotter, positions, parents, errors, bound, radius, carriers=None):
        positions = np.asarray(positions, dtype=float).reshape(-1, 3)
        parents = np.asarray(parents).reshape(-1)
        if carriers is not None:
            carried = np.asarray(carriers, dtype=bool)[np.maximum(parents, 0)]
            parents = np.where(carried, -1, parents)
        self.window = plotter.render_window
        self.renderer = renderer = vtkRenderer()
        renderer.SetLayer(COMPARE_LAYER)
        renderer.InteractiveOff()
        renderer.SetActiveCamera(plotter.renderer.GetActiveCamera())
        renderer.SetViewport(plotter.renderer.GetViewport())
        self.window.SetNumberOfLayers(max(COMPARE_LAYER + 1, self.window.GetNumberOfLayers()))
        self.window.AddRenderer(renderer)
        self.bound = float(bound)
        self.bones = pv.PolyData(positions.copy())
        child = np.flatnonzero(parents >= 0)
        if len(child):
            self.bones.lines = np.column_stack([np.full(len(child), 2), parents[child],
                                                child]).ravel()
        self._xyz = self.bones.points   # VTK's array: written in place each frame
        mapper = vtkPolyDataMapper()
        mapper.SetInputData(self.bones)
        self.line_actor = vtkActor()
        self.line_actor.SetMapper(mapper)
        self.line_actor.PickableOff()
        prop = self.line_actor.GetProperty()
        prop.SetColor(LINE_COLOR)
        prop.SetLineWidth(1.5)
        prop.SetOpacity(0.85)
        self.glyphs = _ErrorGlyphs(positions, RADIUS_FRACTION * radius)
        self.text = vtkTextActor()
        self.text.SetPosition(12, 12)
        tp = self.text.GetTextProperty()
        tp.SetFontSize(15)
        tp.SetColor(0.95, 0.95, 0.95)
        tp.SetBackgroundColor(0.1, 0.1, 0.12)
        tp.SetBackgroundOpacity(0.6)
        self.legend = self._legend()
        self.actors = (self.line_actor, self.glyphs.actor, self.text, self.legend)
        for actor in self.actors:
            renderer.AddActor(actor)
        self.update(positions, errors)

    def _legend(self):
        """A horizontal colour bar, 0 to the bound in centimetres, lower left."""
        ramp = vtkColorTransferFunction()
        cm = self.bound * 100
        for at, rgb in ((0.0, GREEN), (0.5, YELLOW), (1.0, RED)):
            ramp.AddRGBPoint(at * cm, *rgb)
        bar = vtkScalarBarActor()
        bar.SetLookupTable(ramp)
        bar.SetOrientationToHorizontal()
        bar.SetTitle("joint error (cm)")
        bar.SetNumberOfLabels(3)
        bar.SetLabelFormat("%.3g")
        bar.GetPositionCoordinate().SetCoordinateSystemToDisplay()
        bar.GetPositionCoordinate().SetValue(12, 44)
        bar.SetMaximumWidthInPixels(260)
        bar.SetMaximumHeightInPixels(60)
        bar.SetWidth(0.3)
        bar.SetHeight(0.08)
        for tp in (bar.GetTitleTextProperty(), bar.GetLabelTextProperty()):
            tp.SetColor(0.95, 0.95, 0.95)
            tp.SetFontSize(13)
            tp.ItalicOff()
            tp.ShadowOff()
        return bar

    @property
    def colors(self):
        """(J, 3) uint8: each joint's colour now (as VTK holds it)."""
        return np.array(self.glyphs.points.point_data["rgb"])

    @property
    def positions(self):
        """(J, 3) float64: the joints drawn now."""
        return np.array(self._xyz)

    def update(self, positions, errors):
        """Move the joints onto ``positions`` (J, 3) and colour them by ``errors`` (J,)."""
        self._xyz[:] = positions
        self.bones.GetPoints().Modified()
        self.bones.Modified()
        self.glyphs.set_positions(positions)
        self.glyphs.set_colors(error_colors(errors, self.bound))

    def set_text(self, text):
        self.text.SetInput(str(text))

    def set_visible(self, visible):
        for actor in self.actors:
            actor.SetVisibility(bool(visible))

    def remove(self):
        """Take the actors and their renderer out of the render window."""
        for actor in self.actors:
            self.renderer.RemoveActor(actor)
        self.window.RemoveRenderer(self.renderer)
