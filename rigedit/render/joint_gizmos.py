"""Joint gizmos: the joint spheres (one glyph actor) and their mouse handling.

A left press on a sphere starts a drag of that joint, found with rigedit's own ray maths
(:mod:`.ray`: the mouse ray against every joint's sphere, which for picking is never smaller
than a few pixels on screen; the sphere the ray enters first wins); mouse moves drag it in the
view plane through its centre, keeping the grab offset (as ``vtkSphereWidget`` did); the
release ends it. A mouse move with no drag highlights the sphere under the mouse. Never
imports Qt.

The owner passes three callbacks, ``on_start(j)``, ``on_move(j, center)`` and ``on_end(j)``;
exceptions in them, raised inside VTK observers, go to :func:`.observers.record_failure`.
"""
from __future__ import annotations

import numpy as np

from .joint_glyphs import JointGlyphs
from .observers import LeftButtonDrag, remove_observers
from .ray import display_to_world, mouse_ray, pick_sphere, pixel_spacing, world_to_display

__all__ = ["JointGizmos", "gizmo_radius"]


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


class JointGizmos(LeftButtonDrag):
    """Draggable spheres at joint positions.

    Parameters
    ----------
    plotter : pyvista.Plotter or pyvistaqt.QtInteractor
        Its interactor, when it has one, delivers the mouse events; without one (an
        off-screen plotter) the spheres are drawn and dragged only through
        :meth:`start_drag`, :meth:`drag_to` and :meth:`end_drag`.
    positions : (J, 3) float
    radius : float
    on_start, on_move, on_end : callable, optional
    renderer : vtkRenderer, optional
        Where the spheres live; the plotter's renderer by default.
    deform : (J,) bool, optional
        Joints that take skin weight (the others are drawn greyer).
    carriers : (J,) bool, optional
        Carrier roots, drawn dimmer still (:data:`~rigedit.render.joint_glyphs.CARRIER_COLOR`).

    Attributes
    ----------
    glyphs : JointGlyphs
        The drawing (one actor).
    selected, active, hovered : int or None
        The selected joint, the joint being dragged, the joint under the mouse.
    errors : list of str
        Tracebacks of exceptions raised by the callbacks.
    on_error : callable or None
        ``on_error(what)`` is called inside the ``except`` block of a failed callback
        (``sys.exc_info()`` is the exception); None warns instead.
    """

    PRIORITY = 0.5  # below the axis handles (10) and the weight brush (9), above the camera (0)
    PICK_PIXELS = 5.0  # a sphere smaller than this on screen is picked as if this big

    def __init__(self, plotter, positions, radius, on_start=None, on_move=None, on_end=None,
                 renderer=None, deform=None, carriers=None):
        self.plotter = plotter
        self.renderer = renderer or plotter.renderer
        self.on_start, self.on_move, self.on_end = on_start, on_move, on_end
        self.radius = float(radius)
        self.errors = []
        self.on_error = None
        self._grab = None
        self.glyphs = JointGlyphs(positions, self.radius, deform=deform, carriers=carriers)
        self.renderer.AddActor(self.glyphs.actor)
        iren = getattr(plotter.iren, "interactor", None) if plotter.iren is not None else None
        self._iren = iren
        self._observers = [] if iren is None else self.observe(iren, self.PRIORITY,
                                                               "joint gizmo")

    # ------------------------------------------------------------------ state
    def __len__(self):
        return len(self.glyphs)

    @property
    def positions(self):
        """(J, 3) sphere centres (read only; move them with the setters)."""
        return self.glyphs.positions

    @property
    def selected(self):
        return self.glyphs.selected

    @property
    def active(self):
        return self.glyphs.active

    @property
    def hovered(self):
        return self.glyphs.hovered

    @property
    def visible(self):
        return self.glyphs.visible

    def center(self, j):
        return np.array(self.glyphs.positions[j])

    def set_center(self, j, p):
        self.glyphs.set_center(j, p)

    def set_positions(self, positions, skip=None):
        """Move every sphere (but ``skip``, the one under the mouse) onto ``positions``."""
        self.glyphs.set_positions(positions, skip=skip)

    def set_selected(self, j):
        self.glyphs.set_state(selected=j)

    def set_deform(self, deform):
        self.glyphs.set_deform(deform)

    def set_visible(self, visible):
        self.glyphs.set_visible(visible)
        if not visible:
            self.glyphs.set_state(hovered=None)

    def display_position(self, j):
        """(x, y) display (pixel) coordinates of joint ``j``'s sphere centre."""
        x, y, _ = world_to_display(self.renderer, self.center(j))
        return x, y

    # ------------------------------------------------------------------ picking
    def hit(self, x, y):
        """The joint whose sphere the mouse ray through display pixel (x, y) enters first,
        and where: ``(j, t)`` with ``t`` the distance along the ray from the near plane, or
        ``(None, inf)``. Hidden spheres are never hit."""
        if not self.visible or not len(self) or \
                not self.renderer.IsInViewport(int(x), int(y)):
            return None, np.inf
        origin, direction = mouse_ray(self.renderer, x, y)
        rel = self.positions - origin
        along = rel @ direction
        offset, growth = pixel_spacing(self.renderer, x, y)
        pixel = np.linalg.norm(offset[None, :] + along[:, None] * growth[None, :], axis=1)
        radius = np.maximum(self.radius, self.PICK_PIXELS * pixel)
        return pick_sphere(origin, direction, self.positions, radius)

    def pick(self, x, y):
        """The joint under display pixel (x, y), or None."""
        return self.hit(x, y)[0]

    # ------------------------------------------------------------------ dragging
    def start_drag(self, j, x=None, y=None):
        """Begin dragging joint ``j``, grabbed at display pixel (x, y) (its centre by
        default); calls ``on_start(j)``."""
        c0 = self.center(j)
        z = world_to_display(self.renderer, c0)[2]
        if x is None:
            x, y = self.display_position(j)
        self._grab = {"item": j, "center": c0, "depth": z,
                      "at": display_to_world(self.renderer, x, y, z)}
        self.glyphs.set_state(active=j, hovered=None)
        if self.on_start:
            self.on_start(j)

    def drag_to(self, center):
        """Move the dragged sphere to ``center`` (3,) and call ``on_move(j, center)``."""
        if self._grab is None:
            return
        j = self._grab["item"]
        self.set_center(j, center)
        if self.on_move:
            self.on_move(j, np.array(center, dtype=float))

    def drag_to_pixel(self, x, y):
        """Drag to display pixel (x, y): in the view plane through the sphere's centre at the
        press, keeping the offset between the centre and the point grabbed."""
        g = self._grab
        if g is None:
            return
        self.drag_to(g["center"] + display_to_world(self.renderer, x, y, g["depth"]) - g["at"])

    def _drag_ended(self):
        """After ``on_end(j)`` (:meth:`end_drag`); the sphere stays where the owner put it."""
        self.glyphs.set_state(active=None)

    def drag(self, j, center):
        """A whole drag of joint ``j`` to ``center`` in one call: start, one move, end."""
        self.start_drag(j)
        try:
            self.drag_to(center)
        finally:
            self.end_drag()

    def hover(self, iren, x, y):
        """Highlight the sphere a press would grab (none once the mouse left the view)."""
        j = None if x is None else self.pick(x, y)
        if j != self.hovered:
            self.glyphs.set_state(hovered=j)
            iren.Render()

    def remove(self):
        """Stop listening to the interactor and take the actor out of its renderer."""
        remove_observers(self._iren, self._observers)
        self._observers = []
        self._grab = None
        self.renderer.RemoveActor(self.glyphs.actor)

