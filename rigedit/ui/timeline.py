"""The timeline dock: time ruler, key marks, playback, key editing and the clip selector.

Data flow (docs/architecture.md): the ruler paints and reports mouse gestures; the dock turns them
into document calls. Time goes through ``Document.set_time``; on the document's ``"time"``
event the dock samples the current clip and shows the pose with ``Document.set_pose`` (no
undo step), so scrubbing, playback and scripts all take the same path and the 3D view and
gizmos follow. Key and clip edits are :class:`~rigedit.document.Command` objects on the
document's undo stack, one per user action; a clip snapshot (``Clip.state``) is cheap because
tracks are immutable.

Playback is driven by elapsed time (:class:`~rigedit.animation.playback.PlaybackClock` fed
with ``time.perf_counter``) from a QTimer: a slow frame skips ahead.
"""
from __future__ import annotations

import time as _time

import numpy as np
from PyQt5 import QtCore, QtGui, QtWidgets

from ..animation.clip import Clip
from ..animation.clip_names import check_new_clip_name, name_key
from ..animation.interpolate import ROTATION_MODES, VECTOR_MODES
from ..animation.playback import PlaybackClock
from ..document import Command
from .timeline_ruler import TimelineRuler

__all__ = ["TimelineDock", "TimelineRuler"]

def _button(text, tip, slot, checkable=False):
    b = QtWidgets.QToolButton()
    b.setText(text)
    b.setToolTip(tip)
    b.setCheckable(checkable)
    (b.toggled if checkable else b.clicked).connect(slot)
    return b


class TimelineDock(QtWidgets.QDockWidget):
    """Timeline, playback, keys and clips for a :class:`~rigedit.ui.main_window.MainWindow`
    (anything with a ``document`` attribute works).

    Scripts and tests drive it with :meth:`play`, :meth:`pause`, :meth:`stop`,
    :meth:`set_time` and :attr:`time` (seconds), and edit keys with :meth:`insert_key`,
    :meth:`delete_key`, :meth:`move_key`, :meth:`copy_keys`, :meth:`paste_keys`.
    """

    def __init__(self, window):
        super().__init__("Timeline", window)
        self.setObjectName("timeline")
        self.document = window.document
        self.clock = PlaybackClock()
        self.fps = 30.0
        self.auto_key = False
        self.clipboard = None
        self._pose = None
        self._resample = True
        self._own_push = False
        self._key_drag = None
        self._stack_len = len(self.document.undo_stack)
        self.timer = QtCore.QTimer(self)
        self.timer.setTimerType(QtCore.Qt.PreciseTimer)
        self.timer.timeout.connect(self._tick)
        self._build()
        self._shortcuts(window)
        window.installEventFilter(self)
        self.document.subscribe(self._on_document)
        self._reload_clips()

    # ================================================================== widgets
    def _build(self):
        body = QtWidgets.QWidget()
        lay = QtWidgets.QVBoxLayout(body)
        lay.setContentsMargins(4, 2, 4, 2)
        lay.setSpacing(2)
        row1, row2 = QtWidgets.QHBoxLayout(), QtWidgets.QHBoxLayout()
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
        self.duration_spin.valueChanged.connect(self.set_duration)
        self.time_label = QtWidgets.QLabel()
        # A fixed size: a label that may change size re-lays out the whole dock on every
        # playback frame's setText
        self.time_label.setText("9999.99 s   frame 99999.9")
        self.time_label.setFixedSize(max(150, self.time_label.sizeHint().width() + 8),
                                     self.time_label.sizeHint().height())
        for w in (self.stop_button, self.play_button, self.loop_box, QtWidgets.QLabel("Speed"),
                  self.speed_spin, self.fps_spin, QtWidgets.QLabel("  Clip"), self.clip_combo,
                  _button("New", "New empty clip", lambda: self.new_clip()),
                  _button("Rename", "Rename the clip", lambda: self.rename_clip()),
                  _button("Duplicate", "Duplicate the clip", lambda: self.duplicate_clip()),
                  _button("Delete", "Delete the clip", lambda: self.delete_clip()),
                  QtWidgets.QLabel("Duration"), self.duration_spin):
            row1.addWidget(w)
        row1.addStretch(1)
        row1.addWidget(self.time_label)
        self.auto_box = QtWidgets.QCheckBox("Auto-key")
        self.auto_box.setToolTip("Posing writes keys at the current time")
        self.auto_box.toggled.connect(self.set_auto_key)
        self.rot_combo = QtWidgets.QComboBox()
        self.rot_combo.addItems(ROTATION_MODES)
        self.rot_combo.setToolTip("Rotation interpolation of the selected joint (all joints "
                                  "when none is selected)")
        self.rot_combo.activated[str].connect(lambda m: self.set_interpolation(m, "rotation"))
        self.vec_combo = QtWidgets.QComboBox()
        self.vec_combo.addItems(VECTOR_MODES)
        self.vec_combo.setToolTip("Translation and scale interpolation of the selected joint "
                                  "(all joints when none is selected)")
        self.vec_combo.activated[str].connect(lambda m: self.set_interpolation(m, "vector"))
        for w in (_button("◆ Key", "Key the selected joint (all when none) at the current time "
                                  "(K)", lambda: self.insert_key()),
                  _button("Key all", "Key every joint at the current time (Shift+K)",
                          lambda: self.insert_key(all_joints=True)),
                  _button("Delete key", "Delete the selected joint's key (all joints' when "
                                        "none is selected) at the current time",
                          lambda: self.delete_key()),
                  _button("Copy", "Copy the selected joint's values (all) at the current time",
                          lambda: self.copy_keys()),
                  _button("Paste", "Paste copied values as keys at the current time",
                          lambda: self.paste_keys()),
                  self.auto_box, QtWidgets.QLabel("  Rotation"), self.rot_combo,
                  QtWidgets.QLabel("Translation/scale"), self.vec_combo):
            row2.addWidget(w)
        row2.addStretch(1)
        self.ruler = TimelineRuler()
        self.ruler.scrubbed.connect(self._scrub)
        self.ruler.key_drag_started.connect(self._key_drag_start)
        self.ruler.key_dragged.connect(self._key_drag_move)
        self.ruler.key_drag_finished.connect(self._key_drag_end)
        lay.addLayout(row1)
        lay.addLayout(row2)
        lay.addWidget(self.ruler, 1)
        self.setWidget(body)

    def _shortcuts(self, window):
        for seq, slot in (("K", lambda: self.insert_key()),
                          ("Shift+K", lambda: self.insert_key(all_joints=True))):
            sc = QtWidgets.QShortcut(QtGui.QKeySequence(seq), window)
            sc.activated.connect(slot)
        for seq, slot in ((QtGui.QKeySequence.Delete, lambda: self.delete_key()),
                          (QtGui.QKeySequence.Copy, lambda: self.copy_keys()),
                          (QtGui.QKeySequence.Paste, lambda: self.paste_keys())):
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
        """The current :class:`Clip`, or None."""
        name = self.document.current_clip
        return self.document.clips.get(name) if name is not None else None

    @property
    def time(self):
        """Current time in seconds."""
        return self.document.time

    @property
    def playing(self):
        return self.clock.playing

    def _duration(self):
        clip = self.clip
        return clip.duration if clip is not None and clip.duration > 0 else 1.0

    def _joint_name(self):
        j = self.document.selection
        return None if j is None else self.document.skeleton.names[j]

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

    def _show_clip_pose(self):
        clip = self.clip
        if clip is None or self.document.dragging:
            return
        if self._pose is None or self._pose.skeleton is not self.document.skeleton:
            self._pose = self.document.rig.rest_pose()
        clip.sample(self.time, out=self._pose)
        self.document.set_pose(self._pose)

    def _sample_new_rig(self):
        """A new rig shows its clip's pose at the current time. Written into the document's
        pose without a "pose" event: listeners after this one (the window) still hold the old
        rig until the same "rig" event reaches them, and they then show the document's pose
        (a "pose" event now would skin the old mesh with the new rig's joints)."""
        clip = self.clip
        if clip is not None and not self.document.dragging:
            clip.sample(self.time, out=self.document.pose)

    # ================================================================== document events
    def _on_document(self, event, **info):
        if event == "time":
            self._show_clip_pose()
            self._refresh_ruler()
        elif event in ("clip", "rig"):
            if event == "rig":
                self.pause()
                self._pose = None
            self._reload_clips()
            if self._resample and event == "rig":
                self._sample_new_rig()
            elif self._resample:
                self._show_clip_pose()
            self._resample = True
        elif event == "selection":
            self._refresh_ruler()
            self._show_modes()
        elif event == "undo":
            self._maybe_auto_key()

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
        clip, name = self.clip, self._joint_name()
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
        clip, name = self.clip, self._joint_name()
        summary = clip.key_times() if clip is not None else []
        joint = clip.key_times(name) if clip is not None and name is not None else []
        self.ruler.set_data(self._duration(), self.fps, self.time, summary, joint, name)
        t = self.time
        self.time_label.setText(f"{t:6.2f} s   frame {t * self.fps:5.1f}")

    # ================================================================== undoable edits
    def _push(self, command, amend=False):
        self._own_push = True
        try:
            if amend:   # fold into the document's last step (auto-key after a pose edit)
                self.document.undo_stack.amend(command)
            else:
                self.document.push(command)
        finally:
            self._own_push = False
            self._stack_len = len(self.document.undo_stack)

    def _clip_changed(self, resample):
        self._resample = resample
        self.document.emit("clip", name=self.document.current_clip)

    def _edit_clip(self, label, change, resample=True, clip=None, amend=False):
        """Run ``change(clip)`` as one undo step (folded into the last one with ``amend``);
        nothing is recorded when it changed nothing. Returns what ``change`` returned."""
        clip = clip or self.clip
        if clip is None:
            return None
        before = clip.state()
        result = change(clip)
        after = clip.state()
        if (before[1:] == after[1:] and before[0].keys() == after[0].keys()
                and all(before[0][k] is after[0][k] for k in before[0])):
            return result
        clip.restore(before)

        def do():
            clip.restore(after)
            self._clip_changed(resample)

        def undo():
            clip.restore(before)
            self._clip_changed(True)

        self._push(Command(label, do, undo), amend=amend)
        return result

    def _scope(self, all_joints):
        name = self._joint_name()
        return None if all_joints or name is None else [name]

    def insert_key(self, all_joints=False, joints=None, label=None, amend=False):
        """Key the selected joint (every joint when ``all_joints`` or nothing is selected) at
        the current time from the current pose. Creates a clip when there is none."""
        if self.clip is None:
            self.new_clip()
        joints = joints if joints is not None else self._scope(all_joints)
        t = self.time
        what = "all joints" if joints is None else ", ".join(joints)
        return self._edit_clip(label or f"Key {what} at {t:.2f}s",
                               lambda c: c.key_pose(self.document.pose, t, joints),
                               resample=False, amend=amend)

    def _near_key(self, joints, t=None):
        """The key time within half a frame of ``t`` (the current time), or None."""
        clip = self.clip
        if clip is None:
            return None
        t = self.time if t is None else t
        times = clip.key_times() if joints is None else np.unique(np.concatenate(
            [clip.key_times(j) for j in joints]))
        if len(times) == 0:
            return None
        k = times[np.argmin(np.abs(times - t))]
        return float(k) if abs(k - t) <= 0.5 / self.fps + 1e-9 else None

    def delete_key(self, all_joints=False):
        """Delete the selected joint's (or all joints') key at the current time."""
        joints = self._scope(all_joints)
        k = self._near_key(joints)
        if k is None:
            return 0
        return self._edit_clip(f"Delete key at {k:.2f}s",
                               lambda c: c.delete_keys([k], joints))

    def move_key(self, old, new, all_joints=False):
        """Move the key at ``old`` seconds to ``new`` (selected joint, or all)."""
        joints = self._scope(all_joints)
        new = float(min(max(new, 0.0), self._duration()))
        return self._edit_clip(f"Move key {old:.2f}s -> {new:.2f}s",
                               lambda c: c.move_keys({old: new}, joints))

    def copy_keys(self, all_joints=False):
        """Copy the selected joint's (or all) values at the current time."""
        if self.clip is not None:
            self.clipboard = self.clip.copy_keys(self.time, self._scope(all_joints))
        return self.clipboard

    def paste_keys(self):
        """Paste copied values as keys at the current time."""
        if not self.clipboard or self.clip is None:
            return 0
        data = {k: v for k, v in self.clipboard.items() if k[0] in self.document.skeleton.index}
        t = self.time
        return self._edit_clip(f"Paste keys at {t:.2f}s", lambda c: c.paste_keys(data, t))

    def set_interpolation(self, mode, channel="rotation"):
        """Interpolation of the selected joint's (or all) ``rotation`` or ``vector``
        (translation and scale) tracks."""
        name = self._joint_name()
        channels = ("rotation",) if channel == "rotation" else ("translation", "scale")

        def change(c):
            return sum(c.set_interpolation(mode, joint=name, channel=ch) for ch in channels)

        try:
            return self._edit_clip(f"Interpolation {mode}", change)
        except ValueError as exc:
            self._error(str(exc))
            return 0

    def set_duration(self, duration):
        if self.clip is None or abs(duration - self.clip.duration) < 1e-9:
            return
        self._edit_clip(f"Duration {duration:g}s", lambda c: c.set_duration(duration))
        if self.time > duration:
            self.set_time(duration)

    def set_auto_key(self, on):
        self.auto_key = bool(on)
        if self.auto_box.isChecked() != self.auto_key:
            self.auto_box.setChecked(self.auto_key)

    # ------------------------------------------------------------------ key drags
    def _key_drag_start(self, t, all_joints):
        self.pause()
        clip = self.clip
        if clip is None:
            return
        joints = None if all_joints else self._scope(False)
        self._key_drag = {"clip": clip, "before": clip.state(), "old": t, "new": t,
                          "joints": joints}
        self.set_time(t)

    def _key_drag_move(self, t):
        drag = self._key_drag
        if drag is None or t == drag["new"]:
            return
        clip = drag["clip"]
        clip.restore(drag["before"])
        clip.move_keys({drag["old"]: t}, drag["joints"])
        drag["new"] = t
        self._resample = True
        self.document.set_time(t)
        self._refresh_ruler()

    def _key_drag_end(self):
        drag, self._key_drag = self._key_drag, None
        if drag is None or drag["new"] == drag["old"]:
            return
        clip = drag["clip"]
        clip.restore(drag["before"])
        self._edit_clip(f"Move key {drag['old']:.2f}s -> {drag['new']:.2f}s",
                        lambda c: c.move_keys({drag["old"]: drag["new"]}, drag["joints"]),
                        clip=clip)

    # ------------------------------------------------------------------ auto-key
    def _changed_joints(self):
        clip, pose = self.clip, self.document.pose
        ref = clip.sample(self.time)
        moved = (~np.all(np.isclose(pose.translation, ref.translation, atol=1e-7), axis=1)
                 | ~np.all(np.isclose(pose.scale, ref.scale, atol=1e-7), axis=1)
                 | (np.abs(np.sum(pose.rotation * ref.rotation, axis=1)) < 1 - 1e-9))
        return [self.document.skeleton.names[j] for j in np.flatnonzero(moved)]

    def _maybe_auto_key(self):
        n = len(self.document.undo_stack)
        grew, self._stack_len = n > self._stack_len, n
        # a new pose edit (not ours, not an undo) while auto-key is on: key what it moved
        if (grew and not self._own_push and self.auto_key and self.clip is not None
                and self.document.mode == "pose" and not self.document.dragging):
            joints = self._changed_joints()
            if joints:
                # one undo step for the pose edit and its keys, as the user made one edit
                last = self.document.undo_stack.undo_label
                self.insert_key(joints=joints, amend=True,
                                label=f"{last} + auto-key {', '.join(joints)}")

    # ------------------------------------------------------------------ clips
    def _edit_clips(self, label, change):
        """Run ``change()`` (which edits ``document.clips`` and returns the new current
        clip's name) as one undo step."""
        d = self.document
        before = (dict(d.clips), d.current_clip)
        current = change()
        after = (dict(d.clips), current)

        def apply(state):
            clips, name = state
            d.clips.clear()
            d.clips.update(clips)
            for key, clip in clips.items():
                clip.name = key
            d.set_current_clip(name)

        apply(before)
        self._push(Command(label, lambda: apply(after), lambda: apply(before)))

    def _unique(self, base):
        """``base``, or ``base 2``, ``base 3``, ...: the first that no clip has (ignoring
        case, see :mod:`rigedit.animation.clip_names`)."""
        taken = {name_key(n) for n in self.document.clips}
        name, i = base, 2
        while name_key(name) in taken:
            name, i = f"{base} {i}", i + 1
        return name

    def _valid_name(self, name, old=None):
        """``name`` when the rig can take it, else None with the reason shown (status bar)."""
        try:
            return check_new_clip_name(name, self.document.clips, old=old)
        except ValueError as exc:
            self._error(str(exc))
            return None

    def new_clip(self, name=None, duration=2.0):
        """Add an empty clip and make it current. Returns its name, or None (and an error
        in the status bar) for an invalid name."""
        clip = Clip("clip", self.document.skeleton, {}, duration=duration)
        return self.add_clip(clip, name or "clip", lambda n: f"New clip {n}")

    def add_clip(self, clip, base, label):
        """Add ``clip`` (on the document's skeleton) under ``base`` made unique, as one undo
        step, and make it current. ``label`` is the undo step's text, or a function of the
        name. Returns the name, or None (and an error in the status bar) for an invalid name."""
        name = self._valid_name(self._unique(base))
        if name is None:
            return None
        clip.name = name

        def change():
            self.document.clips[name] = clip
            return name

        self._edit_clips(label(name) if callable(label) else label, change)
        return name

    def rename_clip(self, new=None):
        old = self.document.current_clip
        if old is None:
            return None
        if new is None:
            new, ok = QtWidgets.QInputDialog.getText(self, "Rename clip", "Name:", text=old)
            if not ok:
                return None
        new = str(new).strip()
        if new == old:
            return old
        if self._valid_name(new, old=old) is None:
            return None

        def change():
            clips = self.document.clips
            items = [(new if k == old else k, c) for k, c in clips.items()]
            clips.clear()
            clips.update(items)
            return new

        self._edit_clips(f"Rename clip {old} -> {new}", change)
        return new

    def duplicate_clip(self):
        clip = self.clip
        if clip is None:
            return None
        return self.add_clip(clip.copy(), f"{clip.name} copy", f"Duplicate clip {clip.name}")

    def delete_clip(self):
        old = self.document.current_clip
        if old is None:
            return None

        def change():
            del self.document.clips[old]
            return next(iter(self.document.clips), None)

        self.pause()
        self._edit_clips(f"Delete clip {old}", change)
        return old

    def _error(self, message):
        win = self.parent()
        if hasattr(win, "error"):
            win.error("Timeline", message)
        else:
            QtWidgets.QMessageBox.warning(self, "Timeline", message)
