"""Joint gizmos: one VTK sphere widget per joint, and X/Y/Z axis handles at the selected joint.

Never imports Qt. The owner passes three callbacks, ``on_start(j)``, ``on_move(j, center)`` and
``on_end(j)``; exceptions in them are caught (VTK would print and swallow them) and kept in
``errors``; then they go to the owner's ``on_error(what)`` handler (the editor shows and logs
them), or, without one, are re-emitted as warnings so that tests run with warnings as errors
fail.
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


def _record_failure(owner, what):
    """Keep the traceback of a failed VTK callback in ``owner.errors``, then hand the
    exception (still being handled) to ``owner.on_error(what)``, or warn with it."""
    tb = traceback.format_exc()
    owner.errors.append(tb)
    handler = owner.on_error
    if handler is None:
        warnings.warn(f"{what} callback failed:\n{tb}", RuntimeWarning, stacklevel=2)
    else:
        handler(f"The {what} callback")


def world_to_display(renderer, world):
    """(3,) display coordinates (pixels x, y and depth) of a world point in ``renderer``."""
    renderer.SetWorldPoint(*np.asarray(world, dtype=float), 1.0)
    renderer.WorldToDisplay()
    return np.array(renderer.GetDisplayPoint())


def display_to_world(renderer, x, y, z):
    """(3,) world point at display pixel (x, y) and depth ``z`` (0 near plane, 1 far) in
    ``renderer``: the inverse of :func:`world_to_display`."""
    renderer.SetDisplayPoint(float(x), float(y), float(z))
    renderer.DisplayToWorld()
    w = np.array(renderer.GetWorldPoint())
    return w[:3] / w[3]


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
    on_error : callable or None
        ``on_error(what)`` is called inside the ``except`` block of a failed callback
        (``sys.exc_info()`` is the exception); None warns instead.
    """

    def __init__(self, plotter, positions, radius, on_start=None, on_move=None, on_end=None,
                 renderer=None):
        self.plotter = plotter
        self.on_start, self.on_move, self.on_end = on_start, on_move, on_end
        self.radius = float(radius)
        self.selected = None
        self.active = None
        self.errors = []
        self.on_error = None
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
                _record_failure(self, "joint gizmo")
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
        x, y, _ = world_to_display(renderer or self.widgets[j].GetCurrentRenderer(),
                                   self.center(j))
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
    """X, Y and Z arrows at the selected joint, each a handle: a left press on an arrow starts
    a drag constrained to that world axis (Blender's translate gizmo). The toolbar's
    constraint axis is drawn brighter and thicker; the grabbed arrow turns yellow.

    Parameters
    ----------
    plotter : pyvista.Plotter or pyvistaqt.QtInteractor
    length : float
        Arrow length (model units).
    renderer : vtkRenderer, optional
        Where the arrows live (the overlay); the plotter's renderer by default.
    on_start, on_move, on_end : callable, optional
        ``on_start(axis)``, ``on_move(axis, target)`` with ``target`` a (3,) point on the
        axis line through the joint's position at the press, ``on_end(axis)``. Without them
        (or without an interactor) the arrows are only drawn.
    gizmos : JointGizmos, optional
        Its spheres may hide an arrow (a press on a sphere in front goes to the sphere), and
        its ``errors`` list collects exceptions raised in the callbacks.

    Attributes
    ----------
    grabbed : int or None
        The axis being dragged.
    """

    PRIORITY = 10.0  # above the sphere widgets (0.5) and the camera style (0)
    PICK_PIXELS = 6.0  # the shafts are thin: accept presses this close (display pixels)

    def __init__(self, plotter, length, renderer=None, on_start=None, on_move=None,
                 on_end=None, gizmos=None):
        self.plotter = plotter
        self.length = float(length)
        self.renderer = renderer or plotter.renderer
        self.on_start, self.on_move, self.on_end = on_start, on_move, on_end
        self.gizmos = gizmos
        self.errors = gizmos.errors if gizmos is not None else []
        self._on_error = None
        self.actors = []
        self.axis = None
        self.grabbed = None
        self._grab = None
        self._observers = []
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
        iren = getattr(plotter.iren, "interactor", None) if plotter.iren is not None else None
        if iren is not None and on_move is not None:
            self._iren = iren
            for event, fn in (("LeftButtonPressEvent", self._press),
                              ("MouseMoveEvent", self._mouse_move),
                              ("LeftButtonReleaseEvent", self._release)):
                self._observers.append(iren.AddObserver(event, self._guard(fn), self.PRIORITY))

    # ------------------------------------------------------------------ drawing
    def set_position(self, p):
        for a in self.actors:
            a.SetPosition(*np.asarray(p, dtype=float))

    def position(self):
        return np.array(self.actors[0].GetPosition())

    def set_axis(self, axis):
        """Highlight the constraint axis (0, 1, 2) or none."""
        self.axis = axis
        for k, a in enumerate(self.actors):
            on = axis is None or axis == k or self.grabbed == k
            a.GetProperty().SetOpacity(1.0 if on else 0.35)
            a.SetScale(1.25 if axis == k else 1.0)

    def set_grabbed(self, axis):
        """Draw ``axis``'s arrow as grabbed (yellow), or none."""
        self.grabbed = axis
        for k, a in enumerate(self.actors):
            a.GetProperty().SetColor(ACTIVE_COLOR if k == axis else AXIS_COLORS[k])
        self.set_axis(self.axis)

    def set_visible(self, visible):
        for a in self.actors:
            a.SetVisibility(bool(visible))

    @property
    def visible(self):
        return bool(self.actors[0].GetVisibility())

    def tip(self, k, fraction=0.9):
        """World point at ``fraction`` of arrow ``k``'s drawn length (0.9: in the cone)."""
        a = self.actors[k]
        return self.position() + np.eye(3)[k] * self.length * a.GetScale()[k] * fraction

    def display_point(self, world):
        """(x, y, z) display coordinates of a world point in the handles' renderer."""
        return world_to_display(self.renderer, world)

    def ray(self, x, y):
        """The mouse ray through display pixel (x, y): origin on the near plane and unit
        direction, in world coordinates (perspective or parallel camera alike)."""
        near = display_to_world(self.renderer, x, y, 0.0)
        d = display_to_world(self.renderer, x, y, 1.0) - near
        return near, d / np.linalg.norm(d)

    # ------------------------------------------------------------------ picking
    def pick(self, x, y):
        """The arrow under display pixel (x, y), or None.

        Done in display space so that a thin shaft can be grabbed within a few pixels; the
        first part of each arrow, inside the joint's sphere, is left to the sphere, and so
        is any press where a joint sphere lies in front of the arrow.
        """
        if not self.visible or not self.renderer.IsInViewport(int(x), int(y)):
            return None
        mouse = np.array([x, y], dtype=float)
        base = self.display_point(self.position())
        inner = self._sphere_radius() / self.length
        origin, direction = self.ray(x, y)
        best, best_dist, best_depth = None, np.inf, None
        for k in range(3):
            tip = self.display_point(self.tip(k, 1.0))
            seg = tip[:2] - base[:2]
            n2 = float(seg @ seg)
            u = 1.0 if n2 < 1e-12 else float(np.clip((mouse - base[:2]) @ seg / n2, 0, 1))
            if u < inner / self.actors[k].GetScale()[k]:
                continue
            at = base[:2] + u * seg
            # half the drawn thickness near the tip is larger than the shaft's
            thick = self.display_point(self.tip(k, u) + self._side(k) * 0.07 * self.length)
            tol = max(self.PICK_PIXELS, float(np.linalg.norm(thick[:2] - at)))
            dist = float(np.linalg.norm(mouse - at))
            if dist <= tol and dist < best_dist:
                best, best_dist = k, dist
                best_depth = float(np.dot(self.tip(k, u) - origin, direction))
        if best is None or self._sphere_in_front(x, y, best_depth):
            return None
        return best

    def _side(self, k):
        """A unit vector across arrow ``k`` and the view direction (for its drawn width)."""
        view = np.array(self.renderer.GetActiveCamera().GetDirectionOfProjection())
        side = np.cross(np.eye(3)[k], view)
        n = np.linalg.norm(side)
        return side / n if n > 1e-9 else np.zeros(3)

    def _sphere_radius(self):
        return self.gizmos.radius if self.gizmos is not None else 0.0

    def _sphere_in_front(self, x, y, depth):
        """Whether the ray through (x, y) hits a visible joint sphere before ``depth``."""
        g = self.gizmos
        if g is None or not g.visible or not g.widgets:
            return False
        origin, d = self.ray(x, y)
        centers = np.array([w.GetCenter() for w in g.widgets]) - origin
        t = centers @ d
        miss2 = np.einsum("ij,ij->i", centers, centers) - t * t
        hit = miss2 <= g.radius ** 2
        front = t - np.sqrt(np.maximum(g.radius ** 2 - miss2, 0.0))
        return bool(np.any(hit & (front < depth)))

    @staticmethod
    def closest_on_line(point, direction, origin, ray):
        """Parameter ``s`` of the point ``point + s * direction`` closest to the line
        ``origin + t * ray`` (both directions unit), or None when they are parallel."""
        w = point - origin
        b = float(direction @ ray)
        denom = 1.0 - b * b
        if denom < 1e-6:  # looking along the axis: the closest point is undefined
            return None
        return (b * float(ray @ w) - float(direction @ w)) / denom

    # ------------------------------------------------------------------ events
    def _guard(self, fn):
        def callback(obj, event):
            try:
                if fn(obj):
                    obj.GetCommand(self._tag(event)).SetAbortFlag(1)
            except Exception:  # noqa: BLE001 - VTK would swallow it; keep it visible
                _record_failure(self, "axis handle")
        return callback

    @property
    def on_error(self):
        """This one's own handler, else the joint gizmos' it was built with."""
        if self._on_error is not None or self.gizmos is None:
            return self._on_error
        return self.gizmos.on_error

    @on_error.setter
    def on_error(self, handler):
        self._on_error = handler

    def _tag(self, event):
        names = ("LeftButtonPressEvent", "MouseMoveEvent", "LeftButtonReleaseEvent")
        return self._observers[names.index(event)]

    def _press(self, iren):
        """Returns True when the press is ours (the sphere widgets and camera never see it)."""
        if self._grab is not None:
            return True
        x, y = iren.GetEventPosition()
        k = self.pick(x, y)
        if k is None:
            return False
        e = np.eye(3)[k]
        anchor = self.position()
        s0 = self.closest_on_line(anchor, e, *self.ray(x, y))
        self._grab = {"axis": k, "anchor": anchor, "s0": 0.0 if s0 is None else s0,
                      "last": anchor}
        self.set_grabbed(k)
        if self.on_start:
            self.on_start(k)
        iren.Render()
        return True

    def _mouse_move(self, iren):
        grab = self._grab
        if grab is None:
            return False
        k = grab["axis"]
        e = np.eye(3)[k]
        s = self.closest_on_line(grab["anchor"], e, *self.ray(*iren.GetEventPosition()))
        if s is not None:
            # keep the grab offset: the joint moves with the mouse, it does not jump to it
            grab["last"] = grab["anchor"] + (s - grab["s0"]) * e
        if self.on_move:
            self.on_move(k, grab["last"].copy())
        iren.Render()
        return True

    def _release(self, iren):
        grab, self._grab = self._grab, None
        if grab is None:
            return False
        try:
            if self.on_end:
                self.on_end(grab["axis"])
        finally:
            self.set_grabbed(None)
            iren.Render()
        return True

    def remove(self):
        """Stop listening to the interactor (the actors go with the renderer)."""
        iren = getattr(self, "_iren", None)
        if iren is not None:
            for tag in self._observers:
                iren.RemoveObserver(tag)
        self._observers = []
        self._grab = None
