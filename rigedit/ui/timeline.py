"""The timeline dock: its widgets, playback, and the document's events.

Data flow (docs/architecture.md): the ruler paints and reports mouse gestures; the dock turns them
into document calls. Time goes through ``Document.set_time``, which samples the current clip
and shows its pose (no undo step), so scrubbing, playback and scripts all take the same path
and the 3D view and gizmos follow. Key edits (:class:`~rigedit.editor.timeline_keys.KeyEditor`,
the dock's :attr:`~TimelineDock.keys`) and clip edits
(:class:`~rigedit.ui.timeline_clips.ClipManager`, :attr:`~TimelineDock.clip_manager`) are the
editor's commands (:mod:`rigedit.editor.key_commands`, :mod:`rigedit.editor.clip_commands`), one
undo step per user action; the dock follows the document's typed events.

Playback is driven by elapsed time (:class:`~rigedit.editor.playback.PlaybackClock` fed
with ``time.perf_counter``) from a QTimer: a slow frame skips ahead.
"""
from __future__ import annotations

import time as _time

from PyQt5 import QtCore, QtGui, QtWidgets

from ..editor import events as ev
from ..editor.playback import ROTATION_MODES, VECTOR_MODES, PlaybackClock
from ..editor.timeline_keys import KeyEditor
from .timeline_clips import ClipManager
from .timeline_ruler import TimelineRuler

__all__ = ["TimelineDock", "TimelineRuler"]


def _time_text(t, fps):
    return f"{t:6.2f} s   frame {t * fps:5.1f}"


def _button(text, tip, slot, checkable=False):
    b = QtWidgets.QToolButton()
    b.setText(text)
    b.setToolTip(tip)
    b.setCheckable(checkable)
    (b.toggled if checkable else b.clicked).connect(slot)
    return b


class TimelineDock(QtWidgets.QDockWidget):
    """Timeline, playback, keys and clips of the document.

    Scripts and tests drive it with :meth:`play`, :meth:`pause`, :meth:`stop`,
    :meth:`set_time` and :attr:`time` (seconds), edit keys with :attr:`keys`
    (``keys.insert_key()``, ``delete_key``, ``move_key``, ``copy_keys``, ``paste_keys``,
    ``set_interpolation``) and clips with :attr:`clip_manager` (``new_clip``, ``add_clip``,
    ``rename_clip``, ``duplicate_clip``, ``delete_clip``, ``set_duration``).

    Parameters
    ----------
    document : Document
    services : Services
        The dock's parent (``services.parent``) and the error display of a refused edit.
    host : QWidget
        The widget whose K / Shift+K shortcuts key the selection from anywhere in it, and
        whose closing pauses playback (the window: no tick may touch a closing view).

    Attributes
    ----------
    keys : KeyEditor
    clip_manager : ClipManager
    """

    def __init__(self, document, services, host):
        super().__init__("Timeline", services.parent)
        self.setObjectName("timeline")
        self.document = document
        self.services = services
        self.clock = PlaybackClock()
        self.fps = 30.0
        self.clip_manager = ClipManager(self.document, self, self.pause, self.set_time,
                                        self._error)
        self.keys = KeyEditor(self.document, lambda: self.fps, self.set_time, self.pause,
                              self._error)
        self.timer = QtCore.QTimer(self)
        self.timer.setTimerType(QtCore.Qt.PreciseTimer)
        self.timer.timeout.connect(self._tick)
        self._build()
        self._shortcuts(host)
        host.installEventFilter(self)   # its Close pauses playback (eventFilter)
        self.document.listen(self._on_event)
        self._reload_clips()

    # ================================================================== widgets
    def _build(self):
        body = QtWidgets.QWidget()
        lay = QtWidgets.QVBoxLayout(body)
        lay.setContentsMargins(4, 2, 4, 2)
        lay.setSpacing(2)
        self.ruler = TimelineRuler()
        self.ruler.scrubbed.connect(self._scrub)
        self.ruler.key_drag_started.connect(self.keys.key_drag_start)
        self.ruler.key_dragged.connect(self.keys.key_drag_move)
        self.ruler.key_drag_finished.connect(self.keys.key_drag_end)
        lay.addLayout(self._playback_row())
        lay.addLayout(self._keys_row())
        lay.addWidget(self.ruler, 1)
        self.setWidget(body)

    def _playback_row(self):
        """Play, loop, speed, frame rate, the clip and its duration, the time."""
        row1, clips = QtWidgets.QHBoxLayout(), self.clip_manager
        self.stop_button = _button("■ Stop", "Stop and go to the start", self.stop)
        self.play_button = _button("▶ Play", "Play / pause", self.toggle_play)
        self.loop_box = QtWidgets.QCheckBox("Loop")
        self.loop_box.setChecked(True)
        self.loop_box.toggled.connect(lambda on: self.clock.set_loop(on, _time.perf_counter()))
        self.speed_spin = QtWidgets.QDoubleSpinBox()
        self.speed_spin.setRange(-4.0, 4.0)
        self.speed_spin.setSingleStep(0.25)
        self.speed_spin.setValue(1.0)
        self.speed_spin.setSuffix("x")
        self.speed_spin.setToolTip("Playback speed (negative plays backwards)")
        self.speed_spin.valueChanged.connect(self.set_speed)
        self.fps_spin = QtWidgets.QSpinBox()
        self.fps_spin.setRange(1, 120)
        self.fps_spin.setValue(int(self.fps))
        self.fps_spin.setSuffix(" fps")
        self.fps_spin.setToolTip("Frame rate of the ruler, of scrubbing and of playback")
        self.fps_spin.valueChanged.connect(self.set_fps)
        self.clip_combo = QtWidgets.QComboBox()
        self.clip_combo.setMinimumWidth(110)
        self.clip_combo.setToolTip("The clip being edited")
        self.clip_combo.activated[str].connect(self.document.set_current_clip)
        self.duration_spin = QtWidgets.QDoubleSpinBox()
        self.duration_spin.setRange(0.05, 600.0)
        self.duration_spin.setDecimals(2)
        self.duration_spin.setSuffix(" s")
        self.duration_spin.setToolTip("Clip duration")
        self.duration_spin.setKeyboardTracking(False)
        self.duration_spin.valueChanged.connect(self.clip_manager.set_duration)
        self.time_label = QtWidgets.QLabel(_time_text(0.0, self.fps))
        # A fixed size (fitted to the clip's last time by _show_time): a label that may
        # change size re-lays out the whole dock on every playback frame's setText
        self.time_label.setFixedHeight(self.time_label.sizeHint().height())
        for w in (self.stop_button, self.play_button, self.loop_box, QtWidgets.QLabel("Speed"),
                  self.speed_spin, self.fps_spin, QtWidgets.QLabel("  Clip"), self.clip_combo,
                  _button("New", "New empty clip", lambda: clips.new_clip()),
                  _button("Rename", "Rename the clip", lambda: clips.rename_clip()),
                  _button("Duplicate", "Duplicate the clip", lambda: clips.duplicate_clip()),
                  _button("Delete", "Delete the clip", lambda: clips.delete_clip()),
                  QtWidgets.QLabel("Duration"), self.duration_spin):
            row1.addWidget(w)
        row1.addStretch(1)
        row1.addWidget(self.time_label)
        return row1

    def _keys_row(self):
        """Key, delete, copy and paste keys, auto-key, interpolation."""
        row2, keys = QtWidgets.QHBoxLayout(), self.keys
        self.auto_box = QtWidgets.QCheckBox("Auto-key")
        self.auto_box.setToolTip("Posing writes keys at the current time")
        self.auto_box.toggled.connect(self.set_auto_key)
        self.rot_combo = QtWidgets.QComboBox()
        self.rot_combo.addItems(ROTATION_MODES)
        self.rot_combo.setToolTip("Rotation interpolation of the selected joint (all joints "
                                  "when none is selected)")
        self.rot_combo.activated[str].connect(lambda m: keys.set_interpolation(m, "rotation"))
        self.vec_combo = QtWidgets.QComboBox()
        self.vec_combo.addItems(VECTOR_MODES)
        self.vec_combo.setToolTip("Translation and scale interpolation of the selected joint "
                                  "(all joints when none is selected)")
        self.vec_combo.activated[str].connect(lambda m: keys.set_interpolation(m, "vector"))
        for w in (_button("◆ Key", "Key the selected joint (all when none) at the current time "
                                  "(K)", lambda: keys.insert_key()),
                  _button("Key all", "Key every joint at the current time (Shift+K)",
                          lambda: keys.insert_key(all_joints=True)),
                  _button("Delete key", "Delete the selected joint's key (all joints' when "
                                        "none is selected) at the current time",
                          lambda: keys.delete_key()),
                  _button("Copy", "Copy the selected joint's values (all) at the current time",
                          lambda: keys.copy_keys()),
                  _button("Paste", "Paste copied values as keys at the current time",
                          lambda: keys.paste_keys()),
                  self.auto_box, QtWidgets.QLabel("  Rotation"), self.rot_combo,
                  QtWidgets.QLabel("Translation/scale"), self.vec_combo):
            row2.addWidget(w)
        row2.addStretch(1)
        return row2

    def _shortcuts(self, host):
        keys = self.keys
        for seq, slot in (("K", lambda: keys.insert_key()),
                          ("Shift+K", lambda: keys.insert_key(all_joints=True))):
            sc = QtWidgets.QShortcut(QtGui.QKeySequence(seq), host)
            sc.activated.connect(slot)
        for seq, slot in ((QtGui.QKeySequence.Delete, lambda: keys.delete_key()),
                          (QtGui.QKeySequence.Copy, lambda: keys.copy_keys()),
                          (QtGui.QKeySequence.Paste, lambda: keys.paste_keys())):
            sc = QtWidgets.QShortcut(QtGui.QKeySequence(seq), self)
            sc.setContext(QtCore.Qt.WidgetWithChildrenShortcut)
            sc.activated.connect(slot)

    def eventFilter(self, obj, event):
        if event.type() == QtCore.QEvent.Close:
            self.pause()      # no tick may touch a closing window's view
        return False

    # ================================================================== state
    @property
    def clip(self):
        """The current :class:`~rigedit.animation.clip.Clip`, or None."""
        return self.document.clip

    @property
    def time(self):
        """Current time in seconds."""
        return self.document.time

    @property
    def playing(self):
        return self.clock.playing

    def _duration(self):
        """The current clip's duration in seconds (1 without a clip or for an empty one)."""
        clip = self.clip
        return clip.duration if clip is not None and clip.duration > 0 else 1.0

    # ================================================================== time and playback
    def set_time(self, t):
        """Go to ``t`` seconds (clamped to the clip); the character takes the clip's pose."""
        t = float(min(max(t, 0.0), self._duration()))
        self.clock.seek(t, _time.perf_counter())
        self.document.set_time(t)

    def _scrub(self, t):
        self.set_time(t)

    def play(self):
        """Start playback from the current time, in real time."""
        if self.clip is None:
            return
        self.clock.set_duration(self._duration(), _time.perf_counter())
        self.clock.seek(self.time, _time.perf_counter())
        self.clock.play(_time.perf_counter())
        self.timer.start(max(1, int(1000 / self.fps)))
        self.play_button.setText("❚❚ Pause")

    def pause(self):
        self.clock.pause(_time.perf_counter())
        self.timer.stop()
        self.play_button.setText("▶ Play")

    def stop(self):
        self.pause()
        self.clock.stop()
        self.set_time(0.0)

    def toggle_play(self):
        self.pause() if self.playing else self.play()

    def set_speed(self, speed):
        self.clock.set_speed(float(speed), _time.perf_counter())
        if self.speed_spin.value() != speed:
            self.speed_spin.blockSignals(True)
            self.speed_spin.setValue(speed)
            self.speed_spin.blockSignals(False)

    def set_loop(self, on):
        self.loop_box.setChecked(bool(on))

    def set_fps(self, fps):
        self.fps = float(fps)
        if self.timer.isActive():
            self.timer.setInterval(max(1, int(1000 / self.fps)))
        self._refresh_ruler()

    def _tick(self):
        if self.document.dragging:
            return            # the user holds a gizmo: do not fight the drag
        t = self.clock.time(_time.perf_counter())
        self.document.set_time(t)
        if not self.clock.playing:
            self.pause()

    # ================================================================== document events
    def _on_event(self, event):
        if isinstance(event, ev.TimeChanged):
            self._refresh_ruler()
        elif isinstance(event, ev.RigReplaced):
            self.pause()
            self._reload_clips()
        elif isinstance(event, ev.ClipChanged):   # KeysChanged too
            self._reload_clips()
        elif isinstance(event, ev.SelectionChanged):
            self._refresh_ruler()
            self._show_modes()

    def _reload_clips(self):
        d = self.document
        self.clip_combo.blockSignals(True)
        self.clip_combo.clear()
        self.clip_combo.addItems(list(d.clips))
        if d.current_clip is not None:
            self.clip_combo.setCurrentText(d.current_clip)
        self.clip_combo.blockSignals(False)
        self.duration_spin.blockSignals(True)
        self.duration_spin.setValue(self._duration())
        self.duration_spin.blockSignals(False)
        clip = self.clip
        if clip is not None:
            self.loop_box.setChecked(clip.loop)
        self.clock.set_duration(self._duration(), _time.perf_counter())
        self._show_modes()
        self._refresh_ruler()

    def _show_modes(self):
        clip, name = self.clip, self.keys.joint_name()
        if clip is None:
            return
        for combo, channels in ((self.rot_combo, ("rotation",)),
                                (self.vec_combo, ("translation", "scale"))):
            modes = [tr.interpolation for (j, c), tr in clip.tracks.items()
                     if c in channels and (name is None or j == name)]
            combo.blockSignals(True)
            combo.setCurrentText(modes[0] if modes else
                                 "slerp" if channels[0] == "rotation" else "linear")
            combo.blockSignals(False)

    def _refresh_ruler(self):
        clip, name = self.clip, self.keys.joint_name()
        summary = clip.key_times() if clip is not None else []
        joint = clip.key_times(name) if clip is not None and name is not None else []
        self.ruler.set_data(self._duration(), self.fps, self.time, summary, joint, name)
        self._show_time()

    def _show_time(self):
        label = self.time_label
        # the clip's end has the most digits, and digits are of one width in UI fonts
        width = max(130, label.fontMetrics().horizontalAdvance(
            _time_text(self._duration(), self.fps)) + 8)
        if label.width() != width or label.minimumWidth() != width:
            label.setFixedWidth(width)
        label.setText(_time_text(self.time, self.fps))

    # ================================================================== edits
    def set_auto_key(self, on):
        """Posing writes keys at the current time (:attr:`KeyEditor.auto_key`)."""
        self.keys.auto_key = bool(on)
        if self.auto_box.isChecked() != self.keys.auto_key:
            self.auto_box.setChecked(self.keys.auto_key)

    def _error(self, message):
        self.services.error("Timeline", message)
