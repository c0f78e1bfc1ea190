"""The editor's 3D view: the pyvistaqt plotter, the rig's scene, the joint spheres, the axis
handles and the drag controller, rebuilt together when a rig is opened.

It shows the document (its pose in pose mode, the rest pose in edit mode) and holds the view's
options (display mode, what is shown, the weight paint view); the menus' actions that set
them are :mod:`rigedit.ui.view_actions`'s.
"""
from __future__ import annotations

import numpy as np
from PyQt5 import QtCore
from pyvistaqt import QtInteractor

from ..editor.drag import DragController
from ..render.axis_handles import AxisHandles
from ..render.joint_gizmos import JointGizmos, gizmo_radius
from ..render.overlay import overlay_renderer
from ..render.scene import RigScene
from .qt_render import route_renders_through_qt

__all__ = ["SceneView", "BACKGROUND"]

#: One colour, not a gradient: VTK fills a gradient with a full-view quad, which cost 2.6 ms
#: of a 20 ms frame in software OpenGL (a plain clear costs next to nothing; README, Speed)
BACKGROUND = "#2b2f36"


class SceneView:
    """The 3D view of a document.

    Parameters
    ----------
    parent : QWidget
        The plotter's parent (the window; it makes the plotter its central widget).
    document : Document
    drag_settings : DragSettings
        The tool bar's constraint axis and IK chain length (kept across rigs).
    move_rest : callable
        ``move_rest(j, head)`` at the end of an edit-mode drag (see :class:`DragController`).
    status : callable
        ``status(text)``.
    report_exception : callable
        ``report_exception(what)`` inside the ``except`` of a failed VTK callback.

    Attributes
    ----------
    plotter : pyvistaqt.QtInteractor
    scene : RigScene
    overlay : vtkRenderer
        The layer drawn over the mesh (bones, joint spheres, axis arrows).
    gizmos : JointGizmos
    axes : AxisHandles
        The selected joint's X/Y/Z arrows.
    drag : DragController
    radius : float
        The joint spheres' radius (model units).
    display_mode : {"solid", "translucent", "wireframe"}
    skeleton_visible, gizmos_visible, floor_visible, weights_view : bool
    """

    def __init__(self, parent, document, drag_settings, move_rest, status, report_exception):
        self.document = document
        self.drag_settings = drag_settings
        self.move_rest = move_rest
        self.status = status
        self.report_exception = report_exception
        self.scene = self.overlay = self.gizmos = self.axes = self.drag = None
        self.radius = None
        self.display_mode = "solid"
        self.skeleton_visible = self.gizmos_visible = self.floor_visible = True
        self.weights_view = False
        self.plotter = QtInteractor(parent, multi_samples=0, auto_update=False)
        # A native window of its own: Qt then composes the GL view alone on each frame, not
        # the whole window with its docks (about 4 ms of CPU less a frame at 1280x720 here;
        # README, Speed > Dragging)
        self.plotter.setAttribute(QtCore.Qt.WA_NativeWindow)
        self.plotter.set_background(BACKGROUND)
        route_renders_through_qt(self.plotter, lambda: report_exception("Rendering the 3D view"))

    # ------------------------------------------------------------------ building
    def load(self):
        """(Re)build the scene, spheres, handles and drag for the document's rig."""
        self.remove()
        self.plotter.clear()
        self.plotter.enable_lightkit()  # clear() removed the lights too
        rig = self.document.rig
        self.scene = RigScene(self.plotter, rig, show_skeleton=self.skeleton_visible)
        # Bones, joint spheres and axis handles are drawn over the mesh, as "in front".
        self.overlay = overlay_renderer(self.plotter)
        self.overlay.RemoveAllViewProps()
        self.scene.put_bones_on(self.overlay, width=4)
        self.scene.view("front", angle=35)
        self.scene.set_display_mode(self.display_mode)
        if not self.scene.has_mesh and self.weights_view:  # a BVH skeleton: no skin to paint
            self.set_weights_view(False)
        self.scene.set_floor_visible(self.floor_visible)
        self.radius = gizmo_radius(rig)
        self.gizmos = JointGizmos(self.plotter, self.scene.joint_positions, self.radius,
                                  renderer=self.overlay, deform=rig.skeleton.deform,
                                  carriers=self.scene.carriers)
        self.gizmos.on_error = self.report_exception
        self.gizmos.set_visible(self.gizmos_visible)
        self.axes = AxisHandles(self.plotter, 10 * self.radius, renderer=self.overlay,
                                gizmos=self.gizmos, interactive=True)
        self.axes.set_axis(self.drag_settings.axis)
        self.drag = DragController(self.document, self.scene, self.gizmos, self.axes,
                                   self.drag_settings, self.move_rest, self.status,
                                   self.request_render)
        g, a, drag = self.gizmos, self.axes, self.drag
        g.on_start, g.on_move, g.on_end = drag.start, drag.move, drag.end
        # The selected joint's X/Y/Z arrows are handles: a drag on one runs the same code
        # as a sphere drag, constrained to that axis.
        a.on_start, a.on_move, a.on_end = drag.axis_start, drag.axis_move, drag.axis_end
        self.refresh_pose()

    def remove(self):
        """Take the spheres and handles out of the view (before a rebuild, or on close)."""
        if self.axes is not None:
            self.axes.remove()
        if self.gizmos is not None:
            self.gizmos.remove()

    # ------------------------------------------------------------------ the pose
    def shown_pose(self):
        """The pose on screen: the document's in pose mode, the rest pose in edit mode."""
        d = self.document
        return d.pose if d.mode == "pose" else d.rig.rest_pose()

    def refresh_pose(self, skin=True):
        """Show :meth:`shown_pose` (one forward kinematics). Returns its (J, 4, 4) model
        matrices."""
        model = self.document.rig.joint_matrices(self.shown_pose())
        self.scene.update_from_matrices(model, skin=skin)
        heads = model[:, :3, 3]
        self.gizmos.set_positions(heads, skip=self.gizmos.active)
        j = self.document.selection
        if j is not None:
            self.axes.set_position(heads[j])
        return model

    def refresh(self):
        """Show the pose again and ask for a repaint."""
        self.refresh_pose()
        self.request_render()

    @property
    def interacting(self):
        """Whether a gizmo drag is held."""
        return self.drag is not None and self.drag.active

    def request_render(self):
        """Ask Qt to repaint the view once; inside a gizmo drag VTK renders by itself."""
        if not self.interacting:
            self.plotter.update()

    def show_selection(self, j):
        """Mark joint ``j`` (or None) selected: its sphere, its arrows, its weights."""
        self.gizmos.set_selected(j)
        self.axes.set_visible(j is not None and self.gizmos.visible)
        if j is not None:
            self.axes.set_position(self.scene.joint_positions[j])
        if self.weights_view:
            self.show_weights()

    def show_rest_change(self):
        """After a rest edit: a deform flag may have changed, and the weights."""
        self.gizmos.set_deform(self.document.skeleton.deform)
        if self.weights_view:
            self.show_weights()

    # ------------------------------------------------------------------ options
    def set_display_mode(self, mode):
        """"solid", "translucent" (with wireframe) or "wireframe"."""
        self.display_mode = mode
        self.scene.set_display_mode(mode)
        self.request_render()

    def set_skeleton_visible(self, on):
        self.skeleton_visible = bool(on)
        self.scene.set_skeleton_visible(on)
        self.request_render()

    def set_gizmos_visible(self, on):
        self.gizmos_visible = bool(on)
        self.gizmos.set_visible(on)
        self.axes.set_visible(bool(on) and self.document.selection is not None)
        self.request_render()

    def set_floor_visible(self, on):
        self.floor_visible = bool(on)
        self.scene.set_floor_visible(on)
        self.request_render()

    def set_weights_view(self, on):
        """Weight paint view: colour the mesh by the selected joint's influence."""
        self.weights_view = bool(on)
        self.show_weights()
        self.request_render()

    def show_weights(self):
        """Colour the mesh by the selected joint's weights (the weight paint view), or not."""
        if not self.weights_view:
            self.scene.show_weights(None)
            return
        rig, j = self.document.rig, self.document.selection
        w = (np.zeros(len(rig.vertices)) if j is None
             else rig.weights[:, j].toarray().ravel())
        self.scene.show_weights(w)

    def set_skinning(self, method):
        """Skin the view with ``"lbs"`` (linear blend) or ``"dqs"`` (dual quaternions)."""
        self.scene.skinning = method
        self.refresh()

    def view(self, name):
        """Camera preset: "front", "side", "top", "back" or "reset" (three-quarter view)."""
        if name == "reset":
            self.scene.view("front", angle=35)
        else:
            self.scene.view(name)
        self.request_render()

    def set_axis(self, axis):
        """Constrain drags to model axis 0, 1 or 2 (X, Y, Z), or free (None)."""
        self.drag_settings.axis = axis
        self.axes.set_axis(axis)
        self.request_render()

    def close(self):
        self.remove()
        self.plotter.close()
