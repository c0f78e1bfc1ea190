"""The editor window: the wiring of its parts.

Each part is given what it uses (the document, the 3D view, the :class:`~.services.Services`)
and hands back its actions; :func:`~.menus.build_menus` places them all. Data flow: user input
-> :class:`~rigedit.editor.document.Document` methods -> document events -> the parts refresh.

=================  ==========================================================================
part               module
=================  ==========================================================================
3D view            :mod:`.scene_view` (plotter, scene, spheres, axis handles, drags)
view options       :mod:`.view_actions` (View menu, tool bar, pose / edit mode)
Edit menu          :mod:`.edit_actions` (undo, redo, reset, mirror)
docks              :mod:`.panels` (joints, info), :mod:`.timeline` (playback, keys, clips),
                   :mod:`.morph_panel` (shapes), :mod:`.graph_editor` (curves)
File menu          :mod:`.file_actions`, :mod:`.autorig_dialog`, :mod:`.reembed`,
                   :mod:`.import_motion`, :mod:`.record_dialog`, :mod:`.weight_tools`
jobs               :mod:`.jobs` (progress bar, Cancel), :mod:`.rebind` (edit-mode re-binds)
weight brush       :mod:`.weight_brush`
messages           :mod:`.messages` (status line, errors), :mod:`.errors_hook` (bugs)
safety             :mod:`.autosave` (recovery), :mod:`.proxy_view` (big meshes)
=================  ==========================================================================
"""
from __future__ import annotations

import functools

from PyQt5 import QtCore, QtWidgets

from ..editor import events as ev
from ..editor.document import Document
from ..editor.drag import DragSettings
from . import errors_hook
from .autorig_dialog import AutorigAction
from .autosave import Autosave, confirm_unsaved_changes
from .brush_panel import BrushPanel
from .compare_view import CompareCompressed
from .compress_dialog import CompressionSettings, ExportCompressed
from .edit_actions import EditActions
from .fallback import default_rig
from .file_actions import FileActions
from .graph_editor import GraphEditor
from .import_motion import ImportMotion
from .jobs import JobRunner
from .menus import build_menus
from .messages import Messages
from .morph_panel import MorphDock
from .panels import PANEL_PLAYBACK_MS, Panels  # noqa: F401 - PANEL_PLAYBACK_MS: old home
from .proxy_view import ProxyView
from .rebind import RestRebind
from .record_dialog import RecordVideo
from .reembed import ReembedAction
from .scene_view import BACKGROUND, SceneView  # noqa: F401 - BACKGROUND: old home
from .services import Services
from .timeline import TimelineDock
from .view_actions import ViewActions
from .weight_brush import WeightBrush
from .weight_tools import WeightTools
from .window_image import window_image

__all__ = ["MainWindow", "default_rig"]


def _forward(method, part):
    """A window method that calls ``method`` (a function of a part's class) on the window's
    attribute ``part``, with its docstring: the window's API names stay where scripts and
    tests look for them, the work stays in the part."""
    @functools.wraps(method)
    def call(self, *args, **kwargs):
        return method(getattr(self, part), *args, **kwargs)
    return call


class MainWindow(QtWidgets.QMainWindow):
    """The rig editor.

    Parameters
    ----------
    rig : Rig, optional
        The default character when omitted.
    confirm_close : bool
        Ask about unsaved changes on close and before another document replaces this one
        (the app; scripts and tests driving the window do not want the question).

    Attributes
    ----------
    document : Document
        Single source of truth: rig, pose, clips, time, selection, undo stack.
    scene_view : SceneView
        The 3D view; ``plotter``, ``scene``, ``overlay``, ``gizmos``, ``axes``, ``drag`` and
        ``radius`` are its (the last five rebuilt with each rig).
    jobs : JobRunner
        The background job (``job``), its ``progress`` bar and ``cancel_button``.
    view_actions, edit : ViewActions, EditActions
        The View and Edit menus' and the tool bar's actions (``undo_action``,
        ``weights_action``, ``edit_mode_action``, ``mode_label``, ... are theirs).
    panels : Panels
        ``joint_panel`` and ``info_panel`` in their docks.
    timeline : TimelineDock
    graph_editor : GraphEditor
        The graph editor dock (``graph_editor.dock``, hidden until View > Graph editor).
    files, autorig, reembed, motion_import, recorder, weight_tools : the File menu's parts
    export_compressed, compare : File > Export compressed, View > Compare compressed
        (:mod:`.compress_dialog`, :mod:`.compare_view`), sharing ``compression`` (the bound)
    weight_brush : WeightBrush
    rebind : RestRebind
        Edit-mode rest moves re-bound in a worker; Undo cancelling a running one.
    proxy_view : ProxyView
    autosave : Autosave
    error_display : ErrorDisplay
    last_error : str or None
        The last error message shown.
    keep_recovery, confirm_close : bool
        Keep the recovery entry on close (quitting on a signal); ask about unsaved changes.
    """

    def __init__(self, rig=None, parent=None, confirm_close=False):
        super().__init__(parent)
        note = None
        if rig is None:
            rig, note = default_rig()
        self.setWindowTitle("rigedit")
        self.document = d = Document(rig)
        self.drag_settings = DragSettings()
        self.keep_recovery = False   # set when quitting on a signal: the entry must stay
        self.confirm_close = confirm_close
        self._closed = False
        sb = self.statusBar()
        self.messages = Messages(sb, self, lambda: self.autosave.crash_save())
        self.error_display = self.messages.display
        self.jobs = JobRunner(sb, self.status, self.error, self.show_unexpected_error,
                              self.report_exception)
        # the 3D view hands edit-mode rest moves to the re-bind, which refreshes the view
        self.scene_view = view = SceneView(self, d, self.drag_settings,
                                           lambda j, head: self.rebind.move_joint(j, head),
                                           self.status, self.report_exception)
        self.rebind = RestRebind(d, self.jobs.run, self.jobs.current, view.refresh, self.status,
                                 lambda: view.interacting, lambda: self.edit.update())
        self.plotter = self.scene_view.plotter
        self.setCentralWidget(self.plotter)
        services = Services(self, self.status, self.error, self.report_exception,
                            view.request_render, self.jobs)
        self.edit = EditActions(self, d, self.rebind)
        self.jobs.changed.connect(self.edit.update)
        self.view_actions = ViewActions(self, view, d, self.status)
        sb.addPermanentWidget(self.view_actions.mode_label)
        self._build_docks(services)
        self.files = FileActions(d, services, lambda: self.confirm_close,
                                 lambda action: self._may_drop_changes(action),
                                 self.screenshot, self.close)
        self.autorig = AutorigAction(d, services, self.files.replacing)
        self.reembed = ReembedAction(d, services)
        self.motion_import = ImportMotion(d, services, self.timeline.clip_manager.add_clip)
        self.recorder = RecordVideo(d, view, services)
        self.compression = CompressionSettings()   # the export's and the comparison's
        self.export_compressed = ExportCompressed(d, services, self.compression)
        d.listen(self._on_event)   # after the timeline (it samples the clip first)
        self._on_event(ev.RigReplaced())
        self.compare = CompareCompressed(d, view, services, self.compression)   # after the view
        # parts that draw into (or listen to) the scene come once it is built
        self.weight_brush = WeightBrush(d, view, BrushPanel(), self.panels.info_panel,
                                        services, self.set_weights_view)
        self.weight_tools = WeightTools(self, d, view, self.files.recompute_weights,
                                        self.panels.joint_panel)
        # a big mesh is drawn as its decimated proxy while it moves (issue 12)
        self.proxy_view = ProxyView(lambda: view.scene, d, sb, view.request_render,
                                    lambda: view.weights_view)
        self.autosave = Autosave(self, d, self.status, self.error, lambda: view.interacting)
        self._build_menus()
        errors_hook.install(self)
        self.resize(1440, 900)
        self.status(note or f"Loaded {rig.name}: drag a joint sphere to pose; "
                            f"Ctrl+Z undoes")

    def _build_docks(self, services):
        """Right: joints and info; bottom: the timeline."""
        self.panels = Panels(self, self.document, lambda: self.timeline.playing,
                             lambda: self.scene_view.interacting)
        self.joint_panel, self.info_panel = self.panels.joint_panel, self.panels.info_panel
        self.addDockWidget(QtCore.Qt.RightDockWidgetArea, self.panels.joint_dock)
        self.addDockWidget(QtCore.Qt.RightDockWidgetArea, self.panels.info_dock)
        self.setCorner(QtCore.Qt.BottomRightCorner, QtCore.Qt.RightDockWidgetArea)
        self.timeline = TimelineDock(self.document, services, self)
        self.addDockWidget(QtCore.Qt.BottomDockWidgetArea, self.timeline)
        self.morph_dock = MorphDock(self, self.document, self.status)   # right, under Info
        self.graph_editor = GraphEditor(self, self.document, self.timeline, self.status)

    def _build_menus(self):
        parts = (self.files, self.autorig, self.reembed, self.motion_import, self.recorder,
                 self.export_compressed, self.compare, self.edit, self.view_actions,
                 self.panels, self.weight_brush, self.weight_tools, self.morph_dock,
                 self.graph_editor)
        actions = {"timeline_dock": self.timeline.toggleViewAction()}
        for part in parts:
            actions.update(part.actions())
        self.toolbar = build_menus(self, actions)
        # the names scripts and tests use
        v, e = self.view_actions, self.edit
        self.undo_action, self.redo_action = e.undo_action, e.redo_action
        self.weights_action, self.mode_label = v.weights_action, v.mode_label
        self.pose_mode_action, self.edit_mode_action = v.pose_mode_action, v.edit_mode_action
        self.dqs_action = self.weight_tools.dqs_action
        self.recompute_actions = self.weight_tools.recompute_actions
        self.export_video_action = actions["export_video"]
        self.progress, self.cancel_button = self.jobs.progress, self.jobs.cancel_button

    # ================================================================== document events
    def _on_event(self, event):
        """A document event (:mod:`rigedit.editor.events`): the view first, then the docks,
        the Edit menu and the title."""
        d, view = self.document, self.scene_view
        if isinstance(event, ev.RigReplaced):
            view.load()
            self.view_actions.rig_loaded()
        elif isinstance(event, ev.PoseChanged):
            view.refresh_pose()
        elif isinstance(event, (ev.RestChanged, ev.WeightsChanged)):
            view.show_rest_change()
        elif isinstance(event, ev.SelectionChanged):
            view.show_selection(event.joint)
            if event.joint is not None:
                self.status(f"Selected {d.skeleton.names[event.joint]}")
        elif isinstance(event, ev.ModeChanged):
            self.view_actions.mode_changed()
        self.panels.on_event(event)
        if isinstance(event, (ev.RigReplaced, ev.UndoChanged)):
            self.edit.update()
            self._update_title()
        if isinstance(event, (ev.PoseChanged, ev.SelectionChanged)):
            view.request_render()
        elif isinstance(event, ev.RigReplaced):
            self.plotter.update()

    def _update_title(self):
        """"rigedit — name", with a star while there are unsaved changes."""
        d = self.document
        self.setWindowTitle(f"rigedit — {d.rig.name}{' *' if d.modified else ''}")

    # ================================================================== the view's, by name
    scene = property(lambda self: self.scene_view.scene, doc="The rig's :class:`RigScene`.")
    overlay = property(lambda self: self.scene_view.overlay, doc="The layer over the mesh.")
    gizmos = property(lambda self: self.scene_view.gizmos, doc="The joint spheres.")
    axes = property(lambda self: self.scene_view.axes, doc="The selected joint's arrows.")
    drag = property(lambda self: self.scene_view.drag, doc="The :class:`DragController`.")
    radius = property(lambda self: self.scene_view.radius, doc="The joint spheres' radius.")
    interacting = property(lambda self: self.scene_view.interacting, doc="A gizmo drag is held.")
    weights_view = property(lambda self: self.scene_view.weights_view,
                            doc="Whether the weight paint view is on.")
    mode = property(lambda self: self.document.mode, doc='"pose" or "edit".')
    axis = property(lambda self: self.drag_settings.axis,
                    doc="Drag constraint axis (0, 1, 2) or None; set with :meth:`set_axis`.")
    job = property(lambda self: self.jobs.job, doc="The background job running now, or None.")

    @property
    def chain_length(self):
        """IK chain length of a pose-mode drag."""
        return self.drag_settings.chain_length

    @chain_length.setter
    def chain_length(self, n):
        self.drag_settings.chain_length = int(n)

    def show_pose(self, pose):
        """Show ``pose`` (a Pose or (J, 10) snapshot) as the current pose, without an undo
        step (for playback and scrubbing); the view and gizmos follow."""
        self.document.set_pose(pose)

    shown_pose = _forward(SceneView.shown_pose, "scene_view")
    request_render = _forward(SceneView.request_render, "scene_view")
    view = _forward(SceneView.view, "scene_view")
    undo = _forward(EditActions.undo, "edit")
    set_mode = _forward(ViewActions.set_mode, "view_actions")
    set_axis = _forward(ViewActions.set_axis, "view_actions")
    display_mode = _forward(ViewActions.display_mode, "view_actions")
    set_display_mode = _forward(ViewActions.set_display_mode, "view_actions")
    set_skeleton_visible = _forward(ViewActions.set_skeleton_visible, "view_actions")
    set_gizmos_visible = _forward(ViewActions.set_gizmos_visible, "view_actions")
    set_weights_view = _forward(ViewActions.set_weights_view, "view_actions")
    run_job = _forward(JobRunner.run, "jobs")
    cancel_job = _forward(JobRunner.cancel, "jobs")

    def record_video(self, path, fps=30, duration=None, size=(1280, 720), **options):
        """Record the current clip to ``path`` (MP4 or GIF) off-screen, as File > Export video
        does; see :func:`rigedit.ui.record_dialog.record_video`. Returns the frame count."""
        return self.recorder.record(path, fps=fps, duration=duration, size=size, **options)

    # ================================================================== messages
    status = _forward(Messages.status, "messages")
    error = _forward(Messages.error, "messages")
    report_exception = _forward(Messages.report_exception, "messages")
    show_unexpected_error = _forward(Messages.show_unexpected_error, "messages")
    last_error = property(lambda self: self.messages.last_error,
                          doc="The last error message shown.")
    _last_dialog = property(lambda self: self.messages.last_dialog)

    # ================================================================== screenshot, close
    def screenshot(self, path=None):
        """Image of the whole window with the 3D view in it; saved when ``path`` is given.

        Returns
        -------
        QImage
        """
        return window_image(self, self.plotter, path)

    def _may_drop_changes(self, action="closing"):
        """Unsaved changes may go before ``action``: none, saved, or discarded by the user."""
        return confirm_unsaved_changes(self, self.document, self.files.save, action=action)

    def keep_recovery_entry(self):
        """Closing keeps the recovery entry (quitting on a signal: the next start offers it)."""
        self.keep_recovery = True

    def closeEvent(self, event):
        if self._closed:  # closed before (tests close twice): nothing left to ask or free
            super().closeEvent(event)
            return
        if self.confirm_close and not self.keep_recovery and not self._may_drop_changes():
            event.ignore()  # the user chose Cancel, or the save did not happen
            return
        self._closed = True
        self.panels.stop()
        if self.job is not None:
            self.job.cancel()
            self.job.wait(5000)
        self.autosave.stop()
        self.proxy_view.stop()  # a proxy finished after this is not attached to a closed view
        if not self.keep_recovery:
            self.autosave.discard(wait=True)  # a clean close leaves no recovery entry
        errors_hook.uninstall(self)
        self.scene_view.close()
        super().closeEvent(event)
