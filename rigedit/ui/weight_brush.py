"""The weight brush: painting the selected joint's skin weights in the weight paint view.

The maths is :mod:`rigedit.binding.weight_paint`; this module turns mouse events of the 3D view
into dabs. A left-button press on the mesh (brush on) starts a stroke, each mouse move paints
one dab where the mouse ray meets the shown (skinned) surface, and the release makes the whole
stroke one undo step (:meth:`Document.set_weights`). The brush radius is in screen pixels:
at each dab it becomes scene units at the depth of the surface point under the mouse, and the
vertices within that distance of the point are painted with a smooth falloff. A Ctrl+click on
the mesh paints nothing and shows the nearest vertex's influences in the info panel; so does a
plain click (no drag) in the weight paint view while the brush is off.

The press, move and release observers sit on the VTK interactor at a priority between the
axis handles' and the joint spheres' and abort the events they take, so the camera does not
turn while painting; a press that misses the mesh or lands on a joint sphere goes on to the
spheres and the camera as before. The brush's outline is :mod:`rigedit.render.brush_circle`'s,
the mouse ray against the surface :mod:`rigedit.render.surface_pick`'s.
"""
from __future__ import annotations

import numpy as np
from PyQt5 import QtWidgets

from ..editor import events as ev
from ..editor.weight_stroke import BrushTables, WeightStroke
from ..render.brush_circle import BrushCircle
from ..render.observers import add_mouse_observers
from ..render.surface_pick import SurfacePicker, nearest_vertex, world_radius
from .brush_panel import BrushPanel

__all__ = ["BrushPanel", "WeightBrush"]


class WeightBrush:
    """Paints skin weights with the mouse in the editor's 3D view.

    Parameters
    ----------
    document : Document
    view : SceneView
        The 3D view: its plotter, scene, spheres and weight paint view.
    panel : BrushPanel
        The brush's settings.
    info_panel : InfoPanel
        Shows a queried vertex's influences.
    services : Services
        Status, repaint, error display and the parent of the action and tool bar.
    set_weights_view : callable
        ``set_weights_view(True)``: turning the brush on turns the weight paint view on (its
        menu action with it).

    Attributes
    ----------
    enabled : bool
    locked : set of int
        Joints whose weights painting must not change.
    stroke : WeightStroke or None
        The stroke under way.
    errors : list of str
        Tracebacks of exceptions raised in the mouse callbacks (each also shown).
    circle : BrushCircle
        The brush's outline under the mouse.
    action : QAction
        View > Weight brush (checkable).
    toolbar : QToolBar
        The settings row, shown while the brush is on.
    """

    PRIORITY = 9.0  # below the axis handles (10), above the joint spheres (0.5) and camera

    def __init__(self, document, view, panel, info_panel, services, set_weights_view):
        self.document = document
        self.view = view
        self.panel = panel
        self.info_panel = info_panel
        self.status = services.status
        self.request_render = services.request_render
        self.report_exception = services.report_exception
        self.set_weights_view = set_weights_view
        self.enabled = False
        self.locked = set()
        self.stroke = None
        self.tables = BrushTables(document)
        self._click = None  # (x, y, vertex) of a press that may become a plain click
        self.circle = BrushCircle()
        self._picker = SurfacePicker()
        iren = view.plotter.iren.interactor
        self._iren = iren
        self.errors = []  # tracebacks of failed callbacks (see :meth:`on_error`)
        self._observers = add_mouse_observers(
            iren, {"LeftButtonPressEvent": self._press, "MouseMoveEvent": self._move,
                   "LeftButtonReleaseEvent": self._release},
            self.PRIORITY, self, "weight brush")
        tag = iren.AddObserver("LeftButtonReleaseEvent", self._click_release, self.PRIORITY)
        iren.GetCommand(tag).SetPassiveObserver(1)
        self._passive = [tag, iren.AddObserver("LeaveEvent", self._leave)]
        panel.lock_toggled.connect(self._lock_selected)
        self._build_action(services.parent)
        document.listen(self._on_event)
        self._attach()

    def _build_action(self, parent):
        """The checkable "Weight brush" action (View menu and tool bar) and the tool bar row
        of its settings, shown while it is on."""
        action = QtWidgets.QAction("Weight brush", parent)
        action.setCheckable(True)
        action.setToolTip("Paint the selected joint's weights on the mesh (turns on the "
                          "weight paint view)")
        action.setStatusTip(action.toolTip())
        bar = QtWidgets.QToolBar("Weight brush", parent)
        bar.setObjectName("weight-brush")
        bar.setMovable(False)
        bar.addWidget(self.panel)
        bar.setVisible(False)
        action.toggled.connect(self.set_enabled)
        action.toggled.connect(bar.setVisible)
        action.setEnabled(self.view.scene.has_mesh)
        self.action, self.toolbar = action, bar

    def actions(self):
        """name -> QAction or QToolBar for :func:`.menus.build_menus`."""
        return {"weight_brush": self.action, "weight_brush_bar": self.toolbar}

    # ------------------------------------------------------------------ scene
    def _attach(self):
        """Put the circle into the overlay renderer (rebuilt when a rig is opened)."""
        overlay = self.view.overlay or self.view.plotter.renderer
        if not overlay.HasViewProp(self.circle.actor):
            overlay.AddViewProp(self.circle.actor)
        self._picker.reset()
        self.tables.clear()

    def _on_event(self, event):
        if isinstance(event, ev.RigReplaced):
            self.cancel()
            self.locked = set()
            self._attach()
            self.info_panel.show_vertex(None, [])
            if not self.view.scene.has_mesh:
                self.set_enabled(False)
            self.action.setEnabled(self.view.scene.has_mesh)
            self._show_lock()
        elif isinstance(event, ev.SelectionChanged):
            self._show_lock()

    # ------------------------------------------------------------------ settings
    def set_enabled(self, on):
        """Turn the brush on (the weight paint view with it) or off."""
        on = bool(on) and self.view.scene.has_mesh
        self.enabled = on
        if self.action.isChecked() != on:
            self.action.setChecked(on)  # toggled() calls back here with the same value: no loop
        if on and not self.view.weights_view:
            self.set_weights_view(True)
        if not on:
            self.cancel()
            self.circle.actor.VisibilityOff()
        self.status("Weight brush: drag on the mesh to paint the selected joint; "
                      "Ctrl+click shows a vertex's influences" if on else "Weight brush off")
        self.request_render()

    def _lock_selected(self, on):
        j = self.document.selection
        if j is None:
            self.status("Select a joint to lock it")
        elif on:
            self.locked.add(j)
        else:
            self.locked.discard(j)
        self._show_lock()

    def _show_lock(self):
        d = self.document
        names = [d.skeleton.names[j] for j in sorted(self.locked)]
        self.panel.show_lock(d.selection in self.locked, names)

    # ------------------------------------------------------------------ events
    def on_error(self, _what):
        """A mouse callback failed (called by :func:`.observers.record_failure` inside its
        ``except``): the stroke is dropped and the error shown."""
        self.cancel()
        self.report_exception("Weight brush")

    def _active(self):
        return self.enabled and self.view.weights_view and self.view.scene.has_mesh

    def _press(self, iren):
        """Returns True when the press is the brush's (a stroke or a vertex query)."""
        x, y = iren.GetEventPosition()
        if not self.view.scene.has_mesh or self._sphere_under(x, y):
            return False
        if iren.GetControlKey():
            hit = self.pick(x, y)
            if hit is None:
                return False
            self.show_vertex(self.nearest_vertex(hit))
            return True
        if not self._active():
            if self.view.weights_view:  # a plain click (no drag) in the view shows a vertex
                hit = self.pick(x, y)
                self._click = None if hit is None else (x, y, self.nearest_vertex(hit))
            return False
        hit = self.pick(x, y)
        if hit is None:
            return False
        d = self.document
        j = d.selection
        if j is None:
            self.status("Select a joint to paint its weights (click its sphere or name)")
            return True
        if j in self.locked:
            self.status(f"{d.skeleton.names[j]} is locked: unlock it to paint it")
            return True
        self.stroke = WeightStroke(d, j)
        self.dab(hit, x, y)
        return True

    def _move(self, iren):
        x, y = iren.GetEventPosition()
        if self.stroke is None:
            if self._active():
                self._show_circle(x, y, self.pick(x, y) is not None)
            return False
        hit = self.pick(x, y)
        if hit is not None:
            self.dab(hit, x, y)
        else:
            self._show_circle(x, y, False)
        return True

    def _release(self, iren):
        if self.stroke is None:
            return False
        self.finish()
        return True

    def _leave(self, _iren, _event):
        """The mouse left the view: no circle where it no longer is."""
        if self.circle.actor.GetVisibility():
            self.circle.actor.VisibilityOff()
            self.request_render()

    def _click_release(self, iren, _event):
        """A passive observer: the camera style grabs the interactor's focus on a press it
        takes, and then only passive observers see the release."""
        click, self._click = self._click, None
        try:
            if click is not None and self.stroke is None and np.hypot(
                    *np.subtract(iren.GetEventPosition(), click[:2])) <= 3:
                self.show_vertex(click[2])
        except Exception:  # noqa: BLE001 - VTK would swallow it; show it
            self.report_exception("Weight brush")

    # ------------------------------------------------------------------ picking
    def pick(self, x, y):
        """The point of the shown mesh under display pixel (x, y), or None
        (:meth:`SurfacePicker.pick <rigedit.render.surface_pick.SurfacePicker.pick>`)."""
        if self.view.scene.mesh_actor is None:
            return None
        return self._picker.pick(self.view.plotter.renderer, self.view.scene.mesh, x, y)

    def _sphere_under(self, x, y):
        """Whether a visible joint sphere is under the mouse (the spheres stay clickable)."""
        g = self.view.gizmos
        return g is not None and g.pick(x, y) is not None

    def world_radius(self, point, pixels):
        """Scene units that ``pixels`` span on screen at the depth of ``point``."""
        return world_radius(self.view.plotter.renderer, point, pixels)

    def nearest_vertex(self, point):
        return nearest_vertex(self.view.scene.mesh.points, point)

    def _show_circle(self, x, y, on_mesh):
        self.circle.show(x, y, self.panel.radius_box.value(), on_mesh)
        self.request_render()

    # ------------------------------------------------------------------ painting
    def dab(self, point, x, y):
        """Paint one dab of the stroke at surface ``point`` (mouse at display (x, y))."""
        s = self.stroke
        p = self.panel
        radius = self.world_radius(point, p.radius_box.value())
        self._show_circle(x, y, True)
        if not radius > 0:
            return
        adjacency = self.tables.adjacency() if p.mode == "smooth" else None
        mirror = self.tables.mirror() if p.mirror_box.isChecked() else None
        if not s.dab(np.asarray(self.view.scene.mesh.points), point, radius, p.mode,
                     p.strength_box.value(), p.value_box.value(), self.locked, adjacency,
                     mirror):
            return
        if self.view.weights_view:
            self.view.scene.show_weights(s.column())
        self.request_render()

    def finish(self):
        """End the stroke: its change becomes one undo step."""
        s, self.stroke = self.stroke, None
        if s is None:
            return
        message = s.commit()
        if message is not None:
            self.status(message)

    def cancel(self):
        """Drop a stroke under way (the shown colours go back to the document's)."""
        if self.stroke is not None:
            self.stroke = None
            if self.view.weights_view:
                self.view.show_weights()

    # ------------------------------------------------------------------ vertex query
    def show_vertex(self, v):
        """Show vertex ``v``'s influences (joint names and weights) in the info panel."""
        rig = self.document.rig
        b = rig.binding
        order = np.argsort(-b.weights[v])
        pairs = [(rig.skeleton.names[b.indices[v, k]], float(b.weights[v, k]))
                 for k in order if b.weights[v, k] > 0]
        self.info_panel.show_vertex(v, pairs)
        self.status(f"Vertex {v}: " + ", ".join(f"{n} {w:.3f}" for n, w in pairs))

    def remove(self):
        for tag in self._observers + self._passive:
            self._iren.RemoveObserver(tag)
        self._observers = self._passive = []
