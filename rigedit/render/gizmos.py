"""Joint gizmos: one VTK sphere widget per joint, and X/Y/Z axis handles at the selected joint.

Never imports Qt. The owner passes three callbacks, ``on_start(j)``, ``on_move(j, center)`` and
``on_end(j)``; exceptions in them are caught (VTK would print and swallow them), kept in
``errors`` and re-emitted as warnings so that tests run with warnings as errors fail.
"""
from __future__ import annotations

import contextlib
import traceback
import warnings

import numpy as np
import pyvista as pv
import vtk

__all__ = ["JointGizmos", "AxisHandles", "gizmo_radius", "overlay_renderer", "AXIS_COLORS"]

SPHERE_COLOR = (0.55, 0.78, 1.0)
SELECTED_COLOR = (1.0, 0.62, 0.10)
ACTIVE_COLOR = (1.0, 0.95, 0.35)  # while being dragged
AXIS_COLORS = ((0.90, 0.25, 0.25), (0.30, 0.80, 0.30), (0.30, 0.50, 0.95))


def gizmo_radius(rig):
    """Joint sphere radius from the character's size and its bone lengths (model units)."""
    lo, hi = rig.bounds()
    extent = float(np.max(hi - lo)) or 1.0
    sk = rig.skeleton
    heads = sk.bind_matrices[:, :3, 3]
    child = np.flatnonzero(sk.parents >= 0)
    lengths = np.linalg.norm(heads[child] - heads[sk.parents[child]], axis=1)
    lengths = lengths[lengths > 1e-6 * extent]
    r = 0.014 * extent
    if len(lengths):
        r = min(r, 0.3 * float(np.median(lengths)))
    return max(r, 1e-4 * extent)


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
    ren = vtk.vtkRenderer()
    ren.SetLayer(1)
    ren.InteractiveOff()
    ren.SetActiveCamera(plotter.renderer.GetActiveCamera())
    ren.SetViewport(plotter.renderer.GetViewport())
    ren_win.SetNumberOfLayers(max(2, ren_win.GetNumberOfLayers()))
    ren_win.AddRenderer(ren)
    plotter._rigedit_overlay = ren
    return ren


@contextlib.contextmanager
def _no_renders(iren):
    """Each widget On()/Off() asks the interactor to render: batch them into none."""
    was = iren.GetEnableRender()
    iren.EnableRenderOff()
    try:
        yield
    finally:
        iren.SetEnableRender(was)


def _sphere_widget_list(plotter):
    """The plotter's list of sphere widgets (closed with it); moved in pyvista 0.47."""
    helper = getattr(plotter, "widgets", None)
    if helper is not None and hasattr(helper, "sphere_widgets"):
        return helper.sphere_widgets
    return plotter.sphere_widgets


class JointGizmos:
    """Draggable spheres at joint positions.

    Parameters
    ----------
    plotter : pyvista.Plotter or pyvistaqt.QtInteractor
        Must have an interactor (not ``off_screen``).
    positions : (J, 3) float
    radius : float
    on_start, on_move, on_end : callable
    renderer : vtkRenderer, optional
        Where the spheres live; the plotter's renderer by default.

    Attributes
    ----------
    widgets : list of vtkSphereWidget
        One per joint, index = joint index (also appended to ``plotter.sphere_widgets``).
    active : int or None
        The joint being dragged.
    errors : list of str
        Tracebacks of exceptions raised by the callbacks.
    """

    def __init__(self, plotter, positions, radius, on_start=None, on_move=None, on_end=None,
                 renderer=None):
        self.plotter = plotter
        self.on_start, self.on_move, self.on_end = on_start, on_move, on_end
        self.radius = float(radius)
        self.selected = None
        self.active = None
        self.errors = []
        self.visible = True
        renderer = renderer or plotter.renderer
        iren = plotter.iren.interactor
        self.widgets = []
        with _no_renders(iren):
            self._create(iren, renderer, positions)

    def _create(self, iren, renderer, positions):
        plotter = self.plotter
        for j, p in enumerate(np.asarray(positions, dtype=float)):
            w = vtk.vtkSphereWidget()
            w.SetInteractor(iren)
            w.SetCurrentRenderer(renderer)
            w.SetDefaultRenderer(renderer)
            w.SetRepresentationToSurface()
            w.SetThetaResolution(16)
            w.SetPhiResolution(12)
            w.ScaleOff()  # right-drag would resize the sphere: meaningless for a joint
            w.GetSphereProperty().SetColor(SPHERE_COLOR)
            w.GetSphereProperty().SetSpecular(0.4)
            w.GetSelectedSphereProperty().SetColor(ACTIVE_COLOR)
            w.SetRadius(self.radius)
            w.SetCenter(*p)
            w.On()
            w.AddObserver("StartInteractionEvent", self._guard(self._start, j))
            w.AddObserver("InteractionEvent", self._guard(self._move, j))
            w.AddObserver("EndInteractionEvent", self._guard(self._end, j))
            self.widgets.append(w)
            _sphere_widget_list(plotter).append(w)

    def _guard(self, fn, j):
        def callback(widget, _event):
            try:
                fn(j, widget)
            except Exception:  # noqa: BLE001 - VTK would swallow it; keep it visible
                tb = traceback.format_exc()
                self.errors.append(tb)
                warnings.warn(f"joint gizmo callback failed:\n{tb}", RuntimeWarning, stacklevel=1)
        return callback

    def _start(self, j, widget):
        self.active = j
        if self.on_start:
            self.on_start(j)

    def _move(self, j, widget):
        if self.on_move:
            self.on_move(j, np.array(widget.GetCenter()))

    def _end(self, j, widget):
        try:
            if self.on_end:
                self.on_end(j)
        finally:
            self.active = None

    # ------------------------------------------------------------------ state
    def center(self, j):
        return np.array(self.widgets[j].GetCenter())

    def set_center(self, j, p):
        self.widgets[j].SetCenter(*np.asarray(p, dtype=float))

    def set_positions(self, positions, skip=None):
        """Move every sphere (but ``skip``, the one under the mouse) onto ``positions``."""
        for j, (w, p) in enumerate(zip(self.widgets, positions)):
            if j != skip:
                w.SetCenter(float(p[0]), float(p[1]), float(p[2]))

    def set_selected(self, j):
        if self.selected is not None and self.selected < len(self.widgets):
            self.widgets[self.selected].GetSphereProperty().SetColor(SPHERE_COLOR)
        self.selected = j
        if j is not None:
            self.widgets[j].GetSphereProperty().SetColor(SELECTED_COLOR)

    def set_visible(self, visible):
        self.visible = bool(visible)
        with _no_renders(self.plotter.iren.interactor):
            for w in self.widgets:
                w.SetEnabled(self.visible)

    def display_position(self, j, renderer=None):
        """(x, y) display (pixel) coordinates of joint ``j``'s sphere centre."""
        ren = renderer or self.widgets[j].GetCurrentRenderer()
        ren.SetWorldPoint(*self.center(j), 1.0)
        ren.WorldToDisplay()
        x, y, _ = ren.GetDisplayPoint()
        return x, y

    def remove(self):
        iren = self.plotter.iren.interactor if self.plotter.iren is not None else None
        with (_no_renders(iren) if iren is not None else contextlib.nullcontext()):
            for w in self.widgets:
                w.Off()
                w.RemoveAllObservers()
                registry = _sphere_widget_list(self.plotter)
                if w in registry:
                    registry.remove(w)
        self.widgets = []


class AxisHandles:
    """X, Y and Z arrows at a point; the active one (a drag constraint) drawn brighter and
    thicker. Not pickable: the constraint is chosen in the UI, the arrows show it."""

    def __init__(self, plotter, length, renderer=None):
        self.plotter = plotter
        self.actors = []
        self.axis = None
        for k in range(3):
            direction = np.eye(3)[k]
            arrow = pv.Arrow(start=(0, 0, 0), direction=direction, scale=length,
                             tip_length=0.25, tip_radius=0.07, shaft_radius=0.025)
            actor = plotter.add_mesh(arrow, color=AXIS_COLORS[k], name=f"axis-handle-{k}",
                                     reset_camera=False, pickable=False, lighting=True)
            if renderer is not None and renderer is not plotter.renderer:
                plotter.renderer.RemoveActor(actor)
                renderer.AddActor(actor)
            self.actors.append(actor)
        self.set_visible(False)

    def set_position(self, p):
        for a in self.actors:
            a.SetPosition(*np.asarray(p, dtype=float))

    def set_axis(self, axis):
        """Highlight the constraint axis (0, 1, 2) or none."""
        self.axis = axis
        for k, a in enumerate(self.actors):
            on = axis is None or axis == k
            a.GetProperty().SetOpacity(1.0 if on else 0.35)
            a.SetScale(1.25 if axis == k else 1.0)

    def set_visible(self, visible):
        for a in self.actors:
            a.SetVisibility(bool(visible))
