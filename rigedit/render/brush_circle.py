"""The weight brush's outline: a circle in display pixels drawn over the 3D view.

A 2D polyline actor (it stays a circle of the brush's pixel radius whatever the camera
does), moved to the mouse at each event and greyed when the mouse is off the mesh. The
brush's mouse handling is :mod:`rigedit.ui.weight_brush`'s. Never imports Qt.
"""
from __future__ import annotations

import numpy as np
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
from vtkmodules.vtkRenderingCore import vtkActor2D, vtkPolyDataMapper2D

__all__ = ["BrushCircle", "CIRCLE_SEGMENTS", "CIRCLE_COLOR", "CIRCLE_OFF_MESH"]

CIRCLE_SEGMENTS = 64
CIRCLE_COLOR = (1.0, 1.0, 1.0)
CIRCLE_OFF_MESH = (0.6, 0.6, 0.6)


class BrushCircle:
    """A circle outline of ``CIRCLE_SEGMENTS`` points in display pixels, hidden at first.

    Attributes
    ----------
    polydata : vtkPolyData
        Its points (display x, y, 0) and one closed line.
    actor : vtkActor2D
        To add to a renderer (the overlay layer in the editor).
    """

    def __init__(self):
        self.polydata = vtkPolyData()
        pts = vtkPoints()
        pts.SetNumberOfPoints(CIRCLE_SEGMENTS)
        self.polydata.SetPoints(pts)
        line = vtkCellArray()
        line.InsertNextCell(CIRCLE_SEGMENTS + 1)
        for k in range(CIRCLE_SEGMENTS + 1):
            line.InsertCellPoint(k % CIRCLE_SEGMENTS)
        self.polydata.SetLines(line)
        mapper = vtkPolyDataMapper2D()
        mapper.SetInputData(self.polydata)
        self.actor = vtkActor2D()
        self.actor.SetMapper(mapper)
        self.actor.GetProperty().SetLineWidth(2.0)
        self.actor.GetProperty().SetColor(*CIRCLE_COLOR)
        self.actor.VisibilityOff()

    def show(self, x, y, radius, on_mesh):
        """Show the circle of ``radius`` pixels about display point (x, y), white over the
        mesh and grey off it (no render)."""
        a = np.linspace(0.0, 2.0 * np.pi, CIRCLE_SEGMENTS, endpoint=False)
        pts = self.polydata.GetPoints()
        for k in range(CIRCLE_SEGMENTS):
            pts.SetPoint(k, x + radius * np.cos(a[k]), y + radius * np.sin(a[k]), 0.0)
        pts.Modified()
        self.polydata.Modified()
        self.actor.GetProperty().SetColor(*(CIRCLE_COLOR if on_mesh else CIRCLE_OFF_MESH))
        self.actor.VisibilityOn()
