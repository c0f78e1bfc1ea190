"""The right-hand docks: the joint panel (tree, rotation sliders, translation and scale) and the
info panel, wired to the document and following its events."""
from __future__ import annotations

from PyQt5 import QtCore, QtWidgets

from ..editor import events as ev
from .joint_panel import InfoPanel, JointPanel

__all__ = ["Panels", "PANEL_PLAYBACK_MS"]

PANEL_PLAYBACK_MS = 100  # the joint panel's refresh interval during playback


class Panels:
    """The joint and info panels in their docks.

    Parameters
    ----------
    parent : QMainWindow
        The docks' parent.
    document : Document
    playing : callable
        ``playing()`` is True while the timeline plays.
    interacting : callable
        ``interacting()`` is True while a gizmo drag is held.

    Attributes
    ----------
    joint_panel : JointPanel
    info_panel : InfoPanel
    joint_dock, info_dock : QDockWidget
    timer : QTimer
        The joint panel's refresh during playback.
    """

    def __init__(self, parent, document, playing, interacting):
        self.document = document
        self.playing = playing
        self.interacting = interacting
        self.closed = False
        self.joint_panel = p = JointPanel()
        self.info_panel = InfoPanel()
        self.timer = QtCore.QTimer(parent)
        self.timer.setSingleShot(True)
        self.timer.setInterval(PANEL_PLAYBACK_MS)
        self.timer.timeout.connect(self.refresh_joint)
        d = document
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
        self.joint_dock = self._dock(parent, "Joints", "joints", p)
        self.joint_dock.setMinimumWidth(330)
        self.info_dock = self._dock(parent, "Info", "info", self.info_panel)

    @staticmethod
    def _dock(parent, title, name, widget):
        dock = QtWidgets.QDockWidget(title, parent)
        dock.setObjectName(name)
        dock.setWidget(widget)
        return dock

    def actions(self):
        """The docks' show/hide actions for :func:`.menus.build_menus`."""
        return {"joints_dock": self.joint_dock.toggleViewAction(),
                "info_dock": self.info_dock.toggleViewAction()}

    # ------------------------------------------------------------------ document events
    def on_event(self, event):
        """Follow a document event (:mod:`rigedit.editor.events`)."""
        d = self.document
        if isinstance(event, ev.RigReplaced):
            self.joint_panel.set_skeleton(d.rig.skeleton)
            self.info_panel.show_rig(d.rig)
            self.info_panel.show_selection(d.rig, None)
        elif isinstance(event, ev.PoseChanged):
            if not d.dragging or not self.interacting():
                self.show_joint_values()
        elif isinstance(event, (ev.RestChanged, ev.WeightsChanged)):
            self.info_panel.show_rig(d.rig)
        elif isinstance(event, ev.SelectionChanged):
            self.joint_panel.show_joint(event.joint, d.pose)
            self.info_panel.show_selection(d.rig, event.joint)
        elif isinstance(event, ev.ClipChanged):   # clips added, removed or renamed
            self.info_panel.labels["Clips"].setText(str(len(d.clips)))

    def show_joint_values(self):
        """The joint panel follows the pose: at once, but during playback at most every
        ``PANEL_PLAYBACK_MS`` (numbers changing 30 times a second cannot be read, and their
        repaint cost about 1 ms of each frame; README, Speed). The last refresh comes after
        the last frame, so a paused panel shows the pose on screen."""
        if self.playing():
            if not self.timer.isActive():
                self.timer.start()
            return
        self.timer.stop()
        self.refresh_joint()

    def refresh_joint(self):
        if not self.closed:   # a refresh due after the window closed has nothing to show
            self.joint_panel.show_joint(self.document.selection, self.document.pose)

    def stop(self):
        self.closed = True
        self.timer.stop()

    # ------------------------------------------------------------------ sliders
    def _euler_live(self, j, angles):
        self.document.begin_drag()
        self.document.pose.set_euler(j, angles, degrees=True)
        self.document.set_pose(self.document.pose, joints=[j])

    def _slider_released(self):
        d = self.document
        j = d.selection
        d.end_drag(f"Rotate {d.skeleton.names[j]}" if j is not None else "Rotate")
