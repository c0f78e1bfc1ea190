"""X, Y and Z arrows at the selected joint, each a handle for an axis-constrained drag.
Never imports Qt."""
from __future__ import annotations

import numpy as np
import pyvista as pv

from .joint_glyphs import ACTIVE_COLOR
from .observers import LeftButtonDrag, remove_observers
from .ray import closest_on_line, mouse_ray, world_to_display

__all__ = ["AxisHandles", "AXIS_COLORS"]

AXIS_COLORS = ((0.90, 0.25, 0.25), (0.30, 0.80, 0.30), (0.30, 0.50, 0.95))


class AxisHandles(LeftButtonDrag):
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
        axis line through the joint's position at the press, ``on_end(axis)``; they may be
        set later.
    interactive : bool, optional
        Whether the arrows take mouse presses (with an interactor); by default when
        ``on_move`` is given. Otherwise the arrows are only drawn.
    gizmos : JointGizmos, optional
        Its spheres may hide an arrow (a press on a sphere in front goes to the sphere), and
        its ``errors`` list collects exceptions raised in the callbacks.

    Attributes
    ----------
    grabbed : int or None
        The axis being dragged.
    """

    PRIORITY = 10.0  # above the joint spheres (0.5) and the camera style (0)
    PICK_PIXELS = 6.0  # the shafts are thin: accept presses this close (display pixels)

    def __init__(self, plotter, length, renderer=None, on_start=None, on_move=None,
                 on_end=None, gizmos=None, interactive=None):
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
        self._iren = iren
        if interactive is None:
            interactive = on_move is not None
        if iren is not None and interactive:
            self._observers = self.observe(iren, self.PRIORITY, "axis handle")

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
        """The mouse ray through display pixel (x, y) (see :func:`.ray.mouse_ray`)."""
        return mouse_ray(self.renderer, x, y)

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
        """Whether the ray through (x, y) enters a visible joint sphere before ``depth``."""
        return self.gizmos is not None and self.gizmos.hit(x, y)[1] < depth

    # ------------------------------------------------------------------ events
    @property
    def on_error(self):
        """This one's own handler, else the joint gizmos' it was built with."""
        if self._on_error is not None or self.gizmos is None:
            return self._on_error
        return self.gizmos.on_error

    @on_error.setter
    def on_error(self, handler):
        self._on_error = handler

    # ------------------------------------------------------------------ dragging
    def start_drag(self, k, x, y):
        """Grab arrow ``k`` at display pixel (x, y); calls ``on_start(k)``."""
        e = np.eye(3)[k]
        anchor = self.position()
        s0 = closest_on_line(anchor, e, *self.ray(x, y))
        self._grab = {"item": k, "anchor": anchor, "s0": 0.0 if s0 is None else s0,
                      "last": anchor}
        self.set_grabbed(k)
        if self.on_start:
            self.on_start(k)

    def drag_to_pixel(self, x, y):
        """The point of the axis line nearest the mouse ray, kept at the grab offset (the
        joint moves with the mouse, it does not jump to it); calls ``on_move(k, target)``."""
        grab = self._grab
        k = grab["item"]
        e = np.eye(3)[k]
        s = closest_on_line(grab["anchor"], e, *self.ray(x, y))
        if s is not None:
            grab["last"] = grab["anchor"] + (s - grab["s0"]) * e
        if self.on_move:
            self.on_move(k, grab["last"].copy())

    def _drag_ended(self):
        self.set_grabbed(None)

    def remove(self):
        """Stop listening to the interactor (the actors go with the renderer)."""
        remove_observers(self._iren, self._observers)
        self._observers = []
        self._grab = None
