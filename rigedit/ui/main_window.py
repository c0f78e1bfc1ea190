"""The editor window: 3D view with joint gizmos, joint and info panels, menus, undo.

Data flow: user input -> :class:`~rigedit.editor.document.Document` methods -> document events ->
:meth:`MainWindow._on_document` refreshes the views. Widgets never talk to each other.
"""
from __future__ import annotations

import sys
import warnings

import numpy as np
from PyQt5 import QtCore, QtWidgets
from pyvistaqt import QtInteractor

from ..editor.document import Document
from ..render.axis_handles import AxisHandles
from ..render.joint_gizmos import JointGizmos, gizmo_radius
from ..render.overlay import overlay_renderer
from ..render.scene import RigScene
from . import errors_hook
from .autosave import Autosave, confirm_unsaved_changes
from ..editor.drag import DragController, DragSettings
from .menus import MenusMixin
from .file_actions import FileActions
from .joint_panel import InfoPanel, JointPanel
from .jobs import JobsMixin
from .rebind import RestRebind
from .weight_brush import install_weight_brush
from .proxy_view import ProxyView
from .weight_tools import install_weight_tools
from .window_image import window_image

__all__ = ["MainWindow", "default_rig"]

#: One colour, not a gradient: VTK fills a gradient with a full-view quad, which cost 2.6 ms
#: of a 20 ms frame in software OpenGL (a plain clear costs next to nothing; README, Speed)
BACKGROUND = "#2b2f36"
PANEL_PLAYBACK_MS = 100  # the joint panel's refresh interval during playback


def default_rig():
    """The bundled quadruped, or the code-built creature when the assets are not installed.

    Returns
    -------
    rig : Rig
    note : str or None
        Why the fallback was used.
    """
    import rigedit

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return rigedit.load_rig(), None
    except (ValueError, OSError) as exc:
        from .fallback import demo_rig

        return demo_rig(), f"bundled quadruped not available ({exc}); showing a demo creature"


class MainWindow(MenusMixin, JobsMixin, QtWidgets.QMainWindow):
    """The rig editor.

    Parameters
    ----------
    rig : Rig, optional
        The default character when omitted.

    Attributes
    ----------
    document : Document
        Single source of truth: rig, pose, clips, time, selection, undo stack.
    plotter : pyvistaqt.QtInteractor
    scene : RigScene
    overlay : vtkRenderer
        The layer drawn over the mesh (bones, joint spheres, axis arrows).
    gizmos : JointGizmos
        The joint spheres (one glyph actor) and their picking; rebuilt with the scene.
    axes : AxisHandles
        The selected joint's X/Y/Z arrows; rebuilt with the scene.
    drag : DragController
        Turns gizmo drags into document edits; rebuilt with the scene.
    drag_settings : DragSettings
        The tool bar's constraint axis and IK chain length (kept across rigs).
    rebind : RestRebind
        Edit-mode rest moves re-bound in a worker; Undo cancelling a running one.
    job : Job or None
        The background job running now (one at a time, :class:`JobsMixin`).
    mode : {"pose", "edit"}
    axis : int or None
        Drag constraint axis (0, 1, 2) or None for free dragging.
    chain_length : int
        IK chain length of a pose-mode drag.
    interacting : bool
        Whether a gizmo drag is held.
    proxy_view : ProxyView
        Draws a big mesh's decimated proxy while it moves, and says so in the status bar.
    radius : float
        The joint spheres' radius (model units), from the rig; set with the scene.
    files : FileActions
        The File menu's work (open, save, export, weights).
    joint_panel, info_panel : JointPanel, InfoPanel
        In the docks ``joint_dock`` and ``info_dock``.
    timeline : TimelineDock
    progress, cancel_button, mode_label : QWidget
        The status bar's job progress, its Cancel and the POSE / EDIT label.
    weight_brush : WeightBrush
    autosave : Autosave
    error_display : ErrorDisplay
        Shows unexpected errors (see :mod:`.errors_hook`).
    last_error : str or None
        The last error message shown.
    keep_recovery, confirm_close : bool
        Keep the recovery entry on close (quitting on a signal); ask about unsaved changes.
    undo_action, redo_action, ... : QAction
        The menus' and tool bar's actions, made by :class:`MenusMixin` (``gizmos_action``,
        ``skeleton_action``, ``floor_action``, ``weights_action``, ``pose_mode_action``,
        ``edit_mode_action``, ``display_actions``, ``axis_actions``, ``chain_spin`` ...).
    """

    def __init__(self, rig=None, parent=None):
        super().__init__(parent)
        note = None
        if rig is None:
            rig, note = default_rig()
        self.setWindowTitle("rigedit")
        self.document = Document(rig)
        self.drag_settings = DragSettings()
        self.last_error = None
        self.job = None
        self.keep_recovery = False   # set when quitting on a signal: the entry must stay
        self.confirm_close = False   # ask about unsaved changes on close (app.py sets it)
        self._closed = False
        self.scene = self.overlay = self.gizmos = self.axes = self.drag = None  # _load_scene
        self.radius = None
        self.rebind = RestRebind(self.document, self.run_job, lambda: self.job,
                                 self._refresh_view, self.status, lambda: self.interacting,
                                 self._update_undo_actions)
        self._weights_view = False
        self._build_view()
        self.files = FileActions(self)
        self._build_actions()
        self._build_panels()
        self._install_docks()
        self._build_status_bar()
        self.document.subscribe(self._on_document)
        self._load_scene()
        self.weight_brush = install_weight_brush(self)  # issue 10: rigedit/ui/weight_brush.py
        install_weight_tools(self)  # DQS toggle, recompute method, deform flag
        # a big mesh is drawn as its decimated proxy while it moves (issue 12)
        self.proxy_view = ProxyView(lambda: self.scene, self.document, self.statusBar(),
                                    self.request_render, lambda: self._weights_view)
        self.autosave = Autosave(self)
        self.error_display = errors_hook.ErrorDisplay(self)
        errors_hook.install(self)
        self.resize(1440, 900)
        self.status(note or f"Loaded {rig.name}: drag a joint sphere to pose; "
                            f"Ctrl+Z undoes")

    # ================================================================== construction
    def _build_view(self):
        self.plotter = QtInteractor(self, multi_samples=0, auto_update=False)
        # A native window of its own: Qt then composes the GL view alone on each frame, not
        # the whole window with its docks (about 4 ms of CPU less a frame at 1280x720 here;
        # README, Speed > Dragging)
        self.plotter.setAttribute(QtCore.Qt.WA_NativeWindow)
        self.plotter.set_background(BACKGROUND)
        self._route_renders_through_qt()
        self.setCentralWidget(self.plotter)

    def _route_renders_through_qt(self):
        """Make VTK's own render requests (a sphere widget after each mouse move, the camera
        style) schedule one Qt paint instead of rendering now: the widget's paint renders
        again anyway, and two renders per mouse move halved the drag rate
        (docs/architecture.md, pitfalls).

        ``vtkRenderWindowInteractor.Render`` always fires ``RenderEvent``, even with
        rendering disabled, so that such a redirect is possible.
        """
        plotter = self.plotter
        iren = plotter.iren.interactor
        rw = plotter.render_window
        iren.EnableRenderOff()

        def on_render_request(_obj, _event):
            try:
                if getattr(plotter, "_in_paint", True):  # inside paintGL: render for real
                    rw.Render()
                else:
                    plotter.update()
            except Exception:  # noqa: BLE001 - VTK would print and swallow it
                self.report_exception("Rendering the 3D view")

        iren.AddObserver("RenderEvent", on_render_request)

    def _build_panels(self):
        self.joint_panel = JointPanel()
        self._panel_timer = QtCore.QTimer(self)
        self._panel_timer.setSingleShot(True)
        self._panel_timer.setInterval(PANEL_PLAYBACK_MS)
        self._panel_timer.timeout.connect(self._refresh_joint_panel)
        p = self.joint_panel
        d = self.document
        p.joint_clicked.connect(d.select)
        p.euler_changed.connect(lambda j, a: d.set_joint_euler(j, a))
        p.slider_pressed.connect(d.begin_drag)
        p.euler_dragged.connect(self._euler_live)
        p.slider_released.connect(self._slider_released)
        p.translation_changed.connect(lambda j, t: d.set_joint_translation(j, t))
        p.scale_changed.connect(lambda j, s: d.set_joint_scale(j, s))
        p.reset_joint.connect(d.reset_joint)
        p.reset_pose.connect(d.reset_pose)
        p.mirror.connect(d.mirror_pose)
        self.info_panel = InfoPanel()

    def _install_docks(self):
        """Where docks go. Right: joints and info. The bottom area is left free for the
        timeline (``self.addDockWidget(Qt.BottomDockWidgetArea, TimelineDock(self))``)."""
        self.joint_dock = QtWidgets.QDockWidget("Joints", self)
        self.joint_dock.setObjectName("joints")
        self.joint_dock.setWidget(self.joint_panel)
        self.joint_dock.setMinimumWidth(330)
        self.addDockWidget(QtCore.Qt.RightDockWidgetArea, self.joint_dock)
        self.info_dock = QtWidgets.QDockWidget("Info", self)
        self.info_dock.setObjectName("info")
        self.info_dock.setWidget(self.info_panel)
        self.addDockWidget(QtCore.Qt.RightDockWidgetArea, self.info_dock)
        self.setCorner(QtCore.Qt.BottomRightCorner, QtCore.Qt.RightDockWidgetArea)
        view = self.menuBar().actions()[2].menu()
        view.addSeparator()
        view.addAction(self.joint_dock.toggleViewAction())
        view.addAction(self.info_dock.toggleViewAction())
        # --- timeline and video export (issue 5) ---
        from .record_dialog import RecordDialog
        from .timeline import TimelineDock
        self.timeline = TimelineDock(self)
        self.addDockWidget(QtCore.Qt.BottomDockWidgetArea, self.timeline)
        view.addAction(self.timeline.toggleViewAction())
        self.export_video_action = self._action("Export &video...", lambda: RecordDialog.run(self))
        file_menu = self.menuBar().actions()[0].menu()
        file_menu.insertAction(next(a for a in file_menu.actions() if a.text().startswith(
            "Save screenshot")), self.export_video_action)
        # --- end timeline ---

    def _build_status_bar(self):
        sb = self.statusBar()
        self.progress = QtWidgets.QProgressBar()
        self.progress.setMaximumWidth(220)
        self.progress.setVisible(False)
        self.cancel_button = QtWidgets.QPushButton("Cancel")
        self.cancel_button.setVisible(False)
        self.cancel_button.clicked.connect(self.cancel_job)
        self.mode_label = QtWidgets.QLabel()
        sb.addPermanentWidget(self.progress)
        sb.addPermanentWidget(self.cancel_button)
        sb.addPermanentWidget(self.mode_label)

    # ================================================================== scene
    def _load_scene(self):
        """(Re)build the 3D scene and panels for the document's rig."""
        if self.axes is not None:
            self.axes.remove()
        if self.gizmos is not None:
            self.gizmos.remove()
        self.plotter.clear()
        self.plotter.enable_lightkit()  # clear() removed the lights too
        rig = self.document.rig
        self.scene = RigScene(self.plotter, rig, show_skeleton=self.skeleton_action.isChecked())
        self.scene.bone_actor.GetProperty().SetLineWidth(4)
        # Bones, joint spheres and axis handles are drawn over the mesh, as "in front".
        self.overlay = overlay_renderer(self.plotter)
        self.overlay.RemoveAllViewProps()
        self.plotter.renderer.RemoveActor(self.scene.bone_actor)
        self.overlay.AddActor(self.scene.bone_actor)
        self.scene.view("front", angle=35)
        self.scene.set_display_mode(self.display_mode())
        # a rig without a mesh (a BVH skeleton) has no skin to shade or paint
        for act in (self.weights_action, *self.display_actions.values()):
            act.setEnabled(self.scene.has_mesh)
        if not self.scene.has_mesh and self._weights_view:
            self.set_weights_view(False)
        self.scene.set_floor_visible(self.floor_action.isChecked())
        self.radius = gizmo_radius(rig)
        self.gizmos = JointGizmos(self.plotter, self.scene.joint_positions, self.radius,
                                  renderer=self.overlay, deform=rig.skeleton.deform)
        self.gizmos.on_error = self.report_exception
        self.gizmos.set_visible(self.gizmos_action.isChecked())
        self.axes = AxisHandles(self.plotter, 10 * self.radius, renderer=self.overlay,
                                gizmos=self.gizmos, interactive=True)
        self.axes.set_axis(self.axis)
        self.drag = DragController(self.document, self.scene, self.gizmos, self.axes,
                                   self.drag_settings, self.rebind.move_joint, self.status,
                                   self.request_render)
        g, a, drag = self.gizmos, self.axes, self.drag
        g.on_start, g.on_move, g.on_end = drag.start, drag.move, drag.end
        # The selected joint's X/Y/Z arrows are handles: a drag on one runs the same code
        # as a sphere drag, constrained to that axis.
        a.on_start, a.on_move, a.on_end = drag.axis_start, drag.axis_move, drag.axis_end
        self.joint_panel.set_skeleton(rig.skeleton)
        self.info_panel.show_rig(rig)
        self.info_panel.show_selection(rig, None)
        self._update_title()
        self._refresh_pose()
        self._update_undo_actions()
        self._update_mode_label()
        self.plotter.update()

    def shown_pose(self):
        """The pose on screen: the document's in pose mode, the rest pose in edit mode."""
        return self.document.pose if self.mode == "pose" else self.document.rig.rest_pose()

    @property
    def mode(self):
        return self.document.mode

    def _refresh_pose(self, skin=True):
        model = self.document.rig.joint_matrices(self.shown_pose())
        self.scene.update_from_matrices(model, skin=skin)
        heads = model[:, :3, 3]
        self.gizmos.set_positions(heads, skip=self.gizmos.active)
        j = self.document.selection
        if j is not None:
            self.axes.set_position(heads[j])
        return model

    def _refresh_view(self):
        self._refresh_pose()
        self.request_render()

    @property
    def interacting(self):
        """Whether a gizmo drag is held."""
        return self.drag is not None and self.drag.active

    @property
    def axis(self):
        """Drag constraint axis (0, 1, 2) or None; set with :meth:`set_axis`."""
        return self.drag_settings.axis

    @property
    def chain_length(self):
        """IK chain length of a pose-mode drag."""
        return self.drag_settings.chain_length

    @chain_length.setter
    def chain_length(self, n):
        self.drag_settings.chain_length = int(n)

    def undo(self):
        """Edit > Undo: cancels a running re-bind when it is the latest edit, else undoes the
        document's last step."""
        return self.rebind.undo()

    def request_render(self):
        """Ask Qt to repaint the view once; inside a gizmo drag VTK renders by itself."""
        if not self.interacting:
            self.plotter.update()

    def show_pose(self, pose):
        """Show ``pose`` (a Pose or (J, 10) snapshot) as the current pose, without an undo
        step (for playback and scrubbing); the view and gizmos follow."""
        self.document.set_pose(pose)

    # ================================================================== document events
    def _on_document(self, event, **info):
        d = self.document
        if event == "rig":
            self._load_scene()
        elif event == "pose":
            self._refresh_pose()
            if not d.dragging or not self.interacting:
                self._show_joint_values()
            self.request_render()
        elif event == "rest":
            self.info_panel.show_rig(d.rig)
            self.gizmos.set_deform(d.skeleton.deform)  # a deform flag may have changed
            if self._weights_view:
                self._show_weights()
        elif event == "selection":
            j = info.get("joint")
            self.gizmos.set_selected(j)
            self.joint_panel.show_joint(j, d.pose)
            self.info_panel.show_selection(d.rig, j)
            self.axes.set_visible(j is not None and self.gizmos.visible)
            if j is not None:
                self.axes.set_position(self.scene.joint_positions[j])
                self.status(f"Selected {d.skeleton.names[j]}")
            if self._weights_view:
                self._show_weights()
            self.request_render()
        elif event == "undo":
            self._update_undo_actions()
            self._update_title()
        elif event == "clip":   # clips added, removed or renamed: the Info count follows
            self.info_panel.labels["Clips"].setText(str(len(d.clips)))

    def _show_joint_values(self):
        """The joint panel follows the pose: at once, but during playback at most every
        ``PANEL_PLAYBACK_MS`` (numbers changing 30 times a second cannot be read, and their
        repaint cost about 1 ms of each frame; README, Speed). The last refresh comes after
        the last frame, so a paused panel shows the pose on screen."""
        if self.timeline.playing:
            if not self._panel_timer.isActive():
                self._panel_timer.start()
            return
        self._panel_timer.stop()
        self._refresh_joint_panel()

    def _refresh_joint_panel(self):
        if not self._closed:   # a refresh due after the window closed has nothing to show
            self.joint_panel.show_joint(self.document.selection, self.document.pose)

    def _update_undo_actions(self):
        s = self.document.undo_stack
        pending = self.rebind.undoable()
        if pending is not None:
            self.undo_action.setEnabled(True)  # undo cancels the running re-bind
            self.undo_action.setText(f"&Undo {pending[2]}")
        else:
            self.undo_action.setEnabled(s.can_undo)
            self.undo_action.setText(f"&Undo {s.undo_label}".strip())
        self.redo_action.setEnabled(s.can_redo)
        self.redo_action.setText(f"&Redo {s.redo_label}".strip())

    def _update_title(self):
        """"rigedit — name", with a star while there are unsaved changes."""
        d = self.document
        self.setWindowTitle(f"rigedit — {d.rig.name}{' *' if d.modified else ''}")

    # ================================================================== view options
    def display_mode(self):
        return next(m for m, a in self.display_actions.items() if a.isChecked())

    def set_display_mode(self, mode):
        """"solid", "translucent" (with wireframe) or "wireframe"."""
        self.display_actions[mode].setChecked(True)
        self.scene.set_display_mode(mode)
        self.request_render()

    def set_skeleton_visible(self, on):
        self.skeleton_action.setChecked(bool(on))
        self.scene.set_skeleton_visible(on)
        self.request_render()

    def set_gizmos_visible(self, on):
        self.gizmos_action.setChecked(bool(on))
        self.gizmos.set_visible(on)
        self.axes.set_visible(bool(on) and self.document.selection is not None)
        self.request_render()

    def _set_floor_visible(self, on):
        self.scene.set_floor_visible(on)
        self.request_render()

    @property
    def weights_view(self):
        """Whether the weight paint view is on (set with :meth:`set_weights_view`)."""
        return self._weights_view

    def set_weights_view(self, on):
        """Weight paint view: colour the mesh by the selected joint's influence."""
        self.weights_action.setChecked(bool(on))
        self._weights_view = bool(on)
        self._show_weights()
        self.request_render()

    def _show_weights(self):
        j = self.document.selection
        if not self._weights_view:
            self.scene.show_weights(None)
            return
        rig = self.document.rig
        w = (np.zeros(len(rig.vertices)) if j is None
             else rig.weights[:, j].toarray().ravel())
        self.scene.show_weights(w)

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
        self.axis_actions[0 if axis is None else axis + 1].setChecked(True)
        self.axes.set_axis(axis)
        self.request_render()

    def set_mode(self, mode):
        """"pose" (drag poses the character) or "edit" (drag moves rest positions)."""
        if mode not in ("pose", "edit"):
            raise ValueError(f"expected mode 'pose' or 'edit', got {mode!r}")
        (self.pose_mode_action if mode == "pose" else self.edit_mode_action).setChecked(True)
        if mode == self.document.mode:
            return
        self.document.mode = mode
        self._refresh_pose()
        self._update_mode_label()
        self.status("Edit mode: drag a joint to move its rest position; the skin is re-bound "
                    "on release" if mode == "edit" else "Pose mode")
        self.request_render()

    def _update_mode_label(self):
        self.mode_label.setText(f"  {self.mode.upper()} MODE  ")
        self.mode_label.setStyleSheet(
            "color: #ffd27a; font-weight: bold" if self.mode == "edit" else "color: #9fd0ff")

    def _euler_live(self, j, angles):
        self.document.begin_drag()
        self.document.pose.set_euler(j, angles, degrees=True)
        self.document.set_pose(self.document.pose, joints=[j])

    def _slider_released(self):
        j = self.document.selection
        self.document.end_drag(f"Rotate {self.document.skeleton.names[j]}" if j is not None
                               else "Rotate")

    def _reset_selected(self):
        if self.document.selection is not None:
            self.document.reset_joint(self.document.selection)

    # ================================================================== messages
    def status(self, text, timeout=0):
        self.statusBar().showMessage(text, timeout)

    def report_exception(self, what=None):
        """Log and show the exception being handled (see :mod:`.errors_hook`); for code that
        must not let it propagate (VTK observers, job callbacks)."""
        errors_hook.report(what, sys.exc_info())

    def show_unexpected_error(self, what, summary):
        """Called by :mod:`.errors_hook` for a bug (not bad input): the document is written
        for recovery first, as the state after a bug may not be trustworthy; then
        :class:`~.errors_hook.ErrorDisplay` shows it."""
        saved = self.autosave.crash_save()
        self.last_error = f"{what} failed: {summary}" if what else summary
        self.error_display.show(what, summary, saved)

    def error(self, title, message):
        """Show one clear message: a dialog (not blocking) and the status bar."""
        self.last_error = message
        self.status(f"Error: {message}")
        box = QtWidgets.QMessageBox(QtWidgets.QMessageBox.Warning, title, message,
                                    QtWidgets.QMessageBox.Ok, self)
        box.setAttribute(QtCore.Qt.WA_DeleteOnClose)
        box.open()
        self._last_dialog = box

    def record_video(self, path, fps=30, duration=None, size=(1280, 720), **options):
        """Record the current clip to ``path`` (MP4 or GIF) off-screen, as File > Export video
        does; see :func:`rigedit.ui.record_dialog.record_video`. Returns the frame count."""
        from .record_dialog import record_video  # issue 5
        return record_video(self, path, fps=fps, duration=duration, size=size, **options)

    # ================================================================== screenshot, close
    def screenshot(self, path=None):
        """Image of the whole window with the 3D view in it; saved when ``path`` is given.

        Returns
        -------
        QImage
        """
        return window_image(self, self.plotter, path)

    def closeEvent(self, event):
        if self._closed:  # closed before (tests close twice): nothing left to ask or free
            super().closeEvent(event)
            return
        if self.confirm_close and not self.keep_recovery \
                and not confirm_unsaved_changes(self):
            event.ignore()  # the user chose Cancel, or the save did not happen
            return
        self._closed = True
        self._panel_timer.stop()
        if self.job is not None:
            self.job.cancel()
            self.job.wait(5000)
        self.autosave.stop()
        self.proxy_view.stop()  # a proxy finished after this is not attached to a closed view
        if not self.keep_recovery:
            self.autosave.discard(wait=True)  # a clean close leaves no recovery entry
        errors_hook.uninstall(self)
        if self.axes is not None:
            self.axes.remove()
        if self.gizmos is not None:
            self.gizmos.remove()
        self.plotter.close()
        super().closeEvent(event)
