"""The editor's single source of truth. Pure Python: no Qt, no VTK.

The :class:`Document` holds an editing session (rig, pose, clips, time, selection, mode,
undo stack), samples the current clip at the current time, and applies every edit, each data
change as a :class:`Command` on the :class:`UndoStack`, so it can be undone and redone
exactly. The edits that need more than a few lines (open and save, keys, clips, weights) are
functions taking the document: :mod:`rigedit.editor.commands` lists them all.

Every change is announced to the listeners as one of the typed events of
:mod:`rigedit.editor.events` (:meth:`Document.listen`); listeners registered the old way
(:meth:`Document.subscribe`) receive ``callback(name, **info)``: ``"rig"``, ``"pose"``
(``joints``), ``"rest"``, ``"selection"`` (``joint``), ``"time"`` (``time``), ``"clip"``
(``name``), ``"undo"``, ``"mode"`` (``mode``), ``"morph"`` (``weights``).
"""
from __future__ import annotations

import numpy as np

from ..model.skeleton import Skeleton
from ..model.skinning import SkinBinding
from . import events as ev
from .auto_key import AutoKey
from .mirror import mirror_map, mirror_name, mirror_pose, side_axis
from .morphs import MorphWeights
from .undo import Command, UndoStack

__all__ = ["Command", "UndoStack", "Document", "mirror_name", "mirror_map", "mirror_pose",
           "skeleton_with_moved_joint", "MODES"]

#: The editing modes: pose mode poses the character, edit (bind) mode moves rest positions.
MODES = ("pose", "edit")


class Document:
    """The editor's state: rig, current pose, clips, time, selection, mode, undo stack.

    Parameters
    ----------
    rig : Rig

    Attributes
    ----------
    rig : Rig
    pose : Pose
        The current pose; change it through :meth:`set_pose` or commands, never in place from
        a widget (the document must notify the views).
    selection : int or None
        The selected joint.
    current_clip : str or None
        Name of the clip being edited (a key of ``rig.clips``).
    time : float
        Seconds.
    undo_stack : UndoStack
    mode : {"pose", "edit"}
        Pose mode poses the character; edit (bind) mode moves rest positions. Setting it
        is :meth:`set_mode`.
    auto_key : AutoKey
        When ``auto_key.enabled``, pose edits write keys at the current time.
    morph : MorphWeights
        The morph target weights shown (:mod:`rigedit.editor.morphs`), sampled with the pose.
    modified : bool
        Whether the data differs from what was last saved or opened (undoing back to the
        saved state makes it false again).
    """

    def __init__(self, rig):
        self._listeners = ev.Listeners()
        self.undo_stack = UndoStack()
        self.undo_stack.observers.append(lambda: self.emit("undo"))
        self._mode = "pose"
        self._drag_before = None
        self.morph = MorphWeights(self)
        self._set_rig(rig)
        self._saved_top = None  # the undo stack's top command when last saved or opened
        self.auto_key = AutoKey(self)   # watches the undo stack before the listeners hear

    # ------------------------------------------------------------------ listeners
    def listen(self, callback):
        """Call ``callback(event)`` with each :mod:`~rigedit.editor.events` event; returns
        ``callback``."""
        return self._listeners.listen(callback)

    def subscribe(self, callback):
        """Call ``callback(name, **info)`` on every change (the string protocol kept for
        views written before the typed events); returns ``callback``."""
        return self._listeners.subscribe(callback)

    def unsubscribe(self, callback):
        """Stop calling ``callback`` (registered with either method)."""
        self._listeners.remove(callback)

    def emit(self, event, **info):
        """Tell every listener about ``event``: an :class:`~rigedit.editor.events.Event`, or
        an old event name with its keywords (``emit("clip", name=...)``)."""
        if event == "undo":   # filled in here: the old name carries nothing
            s = self.undo_stack
            event = ev.UndoChanged(s.undo_label, s.redo_label, self.modified)
        elif isinstance(event, str):
            event = ev.from_name(event, **info)
        self._listeners.emit(event)

    # ------------------------------------------------------------------ rig
    def _set_rig(self, rig):
        self.rig = rig
        self.pose = rig.rest_pose()
        self.selection = None
        self.current_clip = next(iter(rig.clips), None)
        self.time = 0.0
        if len(rig.vertices) == 0 and self.current_clip is not None:
            # a mesh-less skeleton's (BVH) rest is arbitrary: show the motion's first frame
            self._sample_into_pose()
        self.mirror = mirror_map(rig.skeleton.names)

    def set_rig(self, rig, modified=False):
        """Replace the rig (a file was opened): selection cleared, history cleared, the
        pose of the first clip at time 0 (the rest pose without clips). ``modified`` marks
        it unsaved (a recovered document)."""
        self._set_rig(rig)
        self._sample_into_pose()
        self.undo_stack.clear()
        self._saved_top = _NEVER_SAVED if modified else None
        self.emit(ev.RigReplaced())

    # ------------------------------------------------------------------ saved state
    @property
    def modified(self):
        return self.undo_stack.top is not self._saved_top

    def mark_saved(self):
        """The current state is what is on disk (after a successful save)."""
        self._saved_top = self.undo_stack.top
        self.emit("undo")

    def mark_modified(self):
        """The current state is not on disk, whatever the history says (recovered work)."""
        self._saved_top = _NEVER_SAVED
        self.emit("undo")

    skeleton = property(lambda self: self.rig.skeleton)
    clips = property(lambda self: self.rig.clips)

    @property
    def clip(self):
        """The current :class:`~rigedit.animation.clip.Clip`, or None."""
        return None if self.current_clip is None else self.rig.clips.get(self.current_clip)

    # ------------------------------------------------------------------ mode, selection
    @property
    def mode(self):
        return self._mode

    @mode.setter
    def mode(self, mode):
        self.set_mode(mode)

    def set_mode(self, mode):
        """Switch to ``"pose"`` or ``"edit"`` mode (not an undo step)."""
        if mode not in MODES:
            raise ValueError(f"expected mode 'pose' or 'edit', got {mode!r}")
        if mode != self._mode:
            self._mode = mode
            self.emit(ev.ModeChanged(mode))

    def select(self, joint):
        """Select a joint by index or name (None clears). Not an undo step."""
        j = None if joint is None else self.skeleton.joint_index(joint)
        if j != self.selection:
            self.selection = j
            self.emit(ev.SelectionChanged(j))

    # ------------------------------------------------------------------ time and clips
    def sample(self, t=None):
        """The current clip's pose at ``t`` seconds (default: the current time), a new
        :class:`~rigedit.model.pose.Pose`; None without a clip."""
        clip = self.clip
        if clip is None:
            return None
        return clip.sample(self.time if t is None else float(t), out=self.rig.rest_pose())

    def _sample_into_pose(self):
        """Write the current clip's pose at the current time into :attr:`pose`, without an
        event; False when there is nothing to sample or a drag holds the pose."""
        clip = self.clip
        if clip is None or self.dragging:
            return False
        clip.sample(self.time, out=self.pose)
        self.morph.sample(clip, self.time)   # the weights with the pose (MorphChanged)
        return True

    def set_time(self, t, sample=True):
        """Go to ``t`` seconds; the pose becomes the current clip's there (unless ``sample``
        is false or a drag holds the pose). Not an undo step, as playback and scrubbing."""
        self.time = float(t)
        sampled = sample and self._sample_into_pose()
        self.emit(ev.TimeChanged(self.time))
        if sampled:
            self.emit(ev.PoseChanged())

    def set_current_clip(self, name):
        """Edit clip ``name`` (None: none); the pose becomes its pose at the current time."""
        if name is not None and name not in self.rig.clips:
            raise KeyError(f"unknown clip {name!r}")
        self.current_clip = name
        self.clip_changed(ev.ClipChanged(name))

    def clip_changed(self, event, resample=True):
        """Announce a change of the clips (``event``: ClipChanged or KeysChanged), the pose
        sampled from the current clip again first unless ``resample`` is false (a key just
        written from the pose). Clip commands call it from their do and undo."""
        sampled = resample and self._sample_into_pose()
        self.emit(event)
        if sampled:
            self.emit(ev.PoseChanged())

    # ------------------------------------------------------------------ pose
    def set_pose(self, pose, joints=None):
        """Show ``pose`` (a :class:`Pose` or a (J, 10) snapshot) without an undo step, as
        playback and scrubbing do. ``joints`` hints which joints changed."""
        arr = pose.as_array() if hasattr(pose, "as_array") else np.asarray(pose, dtype=float)
        if arr.shape != (len(self.skeleton), 10):
            raise ValueError(f"expected a pose of {len(self.skeleton)} joints, got shape "
                             f"{arr.shape}")
        self.pose.set_array(arr)
        self.emit(ev.PoseChanged(None if joints is None else tuple(int(j) for j in joints)))

    def pose_snapshot(self):
        """(J, 10) copy of the current pose (see :meth:`Pose.as_array`)."""
        return self.pose.as_array()

    def _pose_command(self, label, before, after):
        return Command(label, lambda: self.set_pose(after), lambda: self.set_pose(before))

    def edit_pose(self, label, change):
        """Apply ``change(pose)`` (which edits the pose in place) as one undo step."""
        before = self.pose_snapshot()
        change(self.pose)
        after = self.pose_snapshot()
        self.pose.set_array(before)
        if not np.array_equal(before, after):
            self.undo_stack.push(self._pose_command(label, before, after))

    def begin_drag(self):
        """Remember the pose before an interactive edit (a drag, a slider held down)."""
        if self._drag_before is None:
            self._drag_before = self.pose_snapshot()

    @property
    def dragging(self):
        return self._drag_before is not None

    def drag_euler(self, joint, angles, degrees=True):
        """One step of an interactive rotation (a slider held): the pose shows it at once;
        :meth:`end_drag` makes the whole of it one undo step."""
        j = self.skeleton.joint_index(joint)
        self.begin_drag()
        self.pose.set_euler(j, angles, degrees=degrees)
        self.emit(ev.PoseChanged((j,)))

    def end_drag(self, label):
        """Close an interactive edit: the whole of it becomes one undo step."""
        before, self._drag_before = self._drag_before, None
        if before is None:
            return
        after = self.pose_snapshot()
        if not np.array_equal(before, after):
            self.undo_stack.push(self._pose_command(label, before, after), execute=False)

    def cancel_drag(self):
        before, self._drag_before = self._drag_before, None
        if before is not None:
            self.set_pose(before)

    def set_joint_euler(self, joint, angles, degrees=True):
        j = self.skeleton.joint_index(joint)
        self.edit_pose(f"Rotate {self.skeleton.names[j]}",
                       lambda p: p.set_euler(j, angles, degrees=degrees))

    def set_joint_translation(self, joint, xyz):
        j = self.skeleton.joint_index(joint)
        self.edit_pose(f"Move {self.skeleton.names[j]}", lambda p: p.set_translation(j, xyz))

    def set_joint_scale(self, joint, xyz):
        j = self.skeleton.joint_index(joint)
        self.edit_pose(f"Scale {self.skeleton.names[j]}", lambda p: p.set_scale(j, xyz))

    def reset_joint(self, joint):
        j = self.skeleton.joint_index(joint)
        self.edit_pose(f"Reset {self.skeleton.names[j]}", lambda p: p.reset(j))

    def reset_pose(self):
        self.edit_pose("Reset pose", lambda p: p.reset())

    def mirror_pose(self, source="L"):
        """Copy each side's joints onto the other side, reflected across the character's
        left-right plane. ``source`` "L" copies left onto right, "R" the reverse."""
        self.edit_pose(f"Mirror pose {source}->{'R' if source == 'L' else 'L'}",
                       lambda p: mirror_pose(p, self.mirror, self.skeleton.names,
                                             self._side_axis(), source))

    def _side_axis(self):   # the model axis running left-right
        return side_axis(self.skeleton, self.mirror)

    # ------------------------------------------------------------------ rest pose and binding
    def rest_state(self):
        """What a bind-mode edit changes: (skeleton, binding, pose snapshot). The binding
        object itself is kept, so undo restores the weights bit for bit."""
        return (self.rig.skeleton, self.rig.binding, self.pose_snapshot())

    def make_rest_state(self, skeleton, indices, weights, pose=None):
        """A state for :meth:`push_rest_edit` from new weights (validated here)."""
        binding = SkinBinding(self.rig.vertices, indices, weights, len(skeleton),
                              morphs=self.rig.morphs)
        return (skeleton, binding, self.pose_snapshot() if pose is None else np.array(pose))

    def apply_rest_state(self, state):
        """Put a :meth:`rest_state` in place; announces WeightsChanged when only the
        binding differs, else RestChanged, then PoseChanged."""
        skeleton, binding, pose = state
        if len(skeleton) != len(self.skeleton) or binding.num_vertices != len(self.rig.vertices):
            raise ValueError("expected a rest state of this rig's joints and vertices")
        same_skeleton, same_binding = skeleton is self.rig.skeleton, binding is self.rig.binding
        binding.set_morph_weights(self.rig.binding.morph_weights)   # the weights shown stay
        self.rig.skeleton, self.pose.skeleton, self.rig.binding = skeleton, skeleton, binding
        self.pose.set_array(pose)
        self.emit(ev.WeightsChanged() if same_skeleton else ev.RestChanged(not same_binding))
        self.emit(ev.PoseChanged())

    def push_rest_edit(self, label, before, after, execute=True):
        """Record a rest/binding change (states from :meth:`rest_state` or
        :meth:`make_rest_state`) as one undo step."""
        self.undo_stack.push(Command(label, lambda: self.apply_rest_state(after),
                                     lambda: self.apply_rest_state(before)), execute=execute)

    def set_weights(self, indices, weights, label="Set weights"):
        """Replace the skin weights, (V, K) each, as one undo step."""
        before = self.rest_state()
        self.push_rest_edit(label, before, self.make_rest_state(before[0], indices, weights))

    # ------------------------------------------------------------------ undo
    def push(self, command, execute=True):
        """Record any :class:`Command` (for other editors, such as the timeline's key edits)."""
        self.undo_stack.push(command, execute=execute)

    def undo(self):
        return self.undo_stack.undo()

    def redo(self):
        return self.undo_stack.redo()


#: A saved-state marker that no command matches: the document is unsaved.
_NEVER_SAVED = object()


def skeleton_with_moved_joint(skeleton, joint, head):
    """A copy of ``skeleton`` with ``joint``'s rest (bind) position moved to ``head``; its
    children keep their model-space positions, so only the bones touching it change.

    Parameters
    ----------
    skeleton : Skeleton
    joint : int
    head : (3,) float
        New model-space position.

    Returns
    -------
    Skeleton
    """
    head = np.asarray(head, dtype=np.float64).reshape(3)
    if not np.all(np.isfinite(head)):
        raise ValueError(f"expected a finite joint position, got {head}")
    sk = skeleton
    # ``head`` is where the joint shows at rest (the rest pose's forward kinematics). A glTF
    # mesh may be bound in a frame of its own (bind matrices != rest FK, e.g. a Z-up mesh):
    # each joint's bind matrix then moves with its rest one through the fixed map
    # bind_j = inv(D_j) @ rest_j, D_j = rest_j @ inv(bind_j); D is the identity otherwise.
    rest = sk.forward(sk.rest_local_matrices())
    bind = sk.bind_matrices.copy()
    d_inv = bind[joint] @ np.linalg.inv(rest[joint])
    old = bind[joint, :3, 3].copy()
    rest[joint, :3, 3] = head
    bind[joint] = d_inv @ rest[joint]
    rest_t = sk.rest_translation.copy()
    for k in [joint, *sk.children(joint)]:
        p = sk.parents[k]
        # The local translation that puts k at its (new) model position under its parent.
        rest_t[k] = rest[k, :3, 3] if p < 0 else (np.linalg.inv(rest[p]) @ np.append(
            rest[k, :3, 3], 1.0))[:3]
    tails = sk.tails.copy()  # tails live in the bind frame
    p = sk.parents[joint]
    if p >= 0 and np.all(np.isfinite(tails[p])) and np.allclose(tails[p], old, atol=1e-9):
        tails[p] = bind[joint, :3, 3]
    return Skeleton(list(sk.names), sk.parents.copy(), rest_t, sk.rest_rotation.copy(),
                    sk.rest_scale.copy(), bind_matrices=bind, tails=tails,
                    deform=sk.deform.copy())
