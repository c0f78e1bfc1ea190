"""The editor's single source of truth and its undo stack. Pure Python: no Qt, no VTK.

Views subscribe with :meth:`Document.subscribe` and are told what changed; user input goes
back through document methods. Every data change is a :class:`Command` on the
:class:`UndoStack`, so it can be undone and redone exactly.

Events emitted (``callback(event, **info)``):

``"rig"``        a new rig was loaded (everything changed)
``"pose"``       the current pose changed (``joints``: indices or None for all)
``"rest"``       the skeleton's rest pose or the skin binding changed
``"selection"``  the selected joint changed (``joint``: index or None)
``"time"``       the current time changed
``"clip"``       the current clip or the clips changed
``"undo"``       the undo stack changed (labels, can undo/redo)
"""
from __future__ import annotations

import numpy as np

from ..model.skeleton import Skeleton
from ..model.skinning import SkinBinding
from .undo import Command, UndoStack

__all__ = ["Command", "UndoStack", "Document", "mirror_name", "mirror_map", "mirror_pose",
           "skeleton_with_moved_joint"]


_MIRROR_PAIRS = [("_L", "_R"), ("_l", "_r"), (".L", ".R"), (".l", ".r"), ("Left", "Right"),
                 ("left", "right"), ("L_", "R_"), ("l_", "r_")]


def mirror_name(name):
    """The name of the other side's joint (``arm_L`` -> ``arm_R``, ``LeftHand`` ->
    ``RightHand``), or None when the name has no side."""
    for a, b in _MIRROR_PAIRS:
        for x, y in ((a, b), (b, a)):
            if x in ("L_", "R_", "l_", "r_"):
                if name.startswith(x):
                    return y + name[len(x):]
            elif x in ("_L", "_R", "_l", "_r", ".L", ".R", ".l", ".r"):
                if name.endswith(x):
                    return name[:-len(x)] + y
                if x + "_" in name or x + "." in name:  # thigh_L_01 style
                    return name.replace(x + "_", y + "_", 1).replace(x + ".", y + ".", 1)
            elif x in name:
                return name.replace(x, y, 1)
    return None


def mirror_map(names):
    """(J,) int: for each joint its mirror's index, or itself when it has none."""
    index = {n: i for i, n in enumerate(names)}
    out = np.arange(len(names))
    for i, n in enumerate(names):
        m = mirror_name(n)
        if m is not None and m in index:
            out[i] = index[m]
    return out


class Document:
    """The editor's state: rig, current pose, clips, time, selection, undo stack.

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
        Pose mode poses the character; edit (bind) mode moves rest positions.
    modified : bool
        Whether the data differs from what was last saved or opened (undoing back to the
        saved state makes it false again).
    """

    def __init__(self, rig):
        self._observers = []
        self.undo_stack = UndoStack()
        self.undo_stack.observers.append(lambda: self.emit("undo"))
        self.mode = "pose"
        self._drag_before = None
        self._set_rig(rig)
        self._saved_top = None  # the undo stack's top command when last saved or opened

    # ------------------------------------------------------------------ observers
    def subscribe(self, callback):
        """Call ``callback(event, **info)`` on every change; returns ``callback``."""
        self._observers.append(callback)
        return callback

    def unsubscribe(self, callback):
        if callback in self._observers:
            self._observers.remove(callback)

    def emit(self, event, **info):
        for cb in list(self._observers):
            cb(event, **info)

    # ------------------------------------------------------------------ rig
    def _set_rig(self, rig):
        self.rig = rig
        self.pose = rig.rest_pose()
        self.selection = None
        self.current_clip = next(iter(rig.clips), None)
        self.time = 0.0
        if len(rig.vertices) == 0 and self.current_clip is not None:
            # a skeleton without a mesh (BVH) has an arbitrary rest pose (Bandai's lies flat):
            # show its motion's first frame, where the timeline starts
            rig.clips[self.current_clip].sample(0.0, out=self.pose)
        self.mirror = mirror_map(rig.skeleton.names)

    def set_rig(self, rig, modified=False):
        """Replace the rig (a file was opened): new pose, selection cleared, history cleared.
        ``modified`` marks it unsaved (a recovered document)."""
        self._set_rig(rig)
        self.undo_stack.clear()
        self._saved_top = _NEVER_SAVED if modified else None
        self.emit("rig")

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

    @property
    def skeleton(self):
        return self.rig.skeleton

    @property
    def clips(self):
        return self.rig.clips

    # ------------------------------------------------------------------ selection, time, clip
    def select(self, joint):
        """Select a joint by index or name (None clears). Not an undo step."""
        j = None if joint is None else self.skeleton.joint_index(joint)
        if j != self.selection:
            self.selection = j
            self.emit("selection", joint=j)

    def set_time(self, t):
        self.time = float(t)
        self.emit("time", time=self.time)

    def set_current_clip(self, name):
        if name is not None and name not in self.rig.clips:
            raise KeyError(f"unknown clip {name!r}")
        self.current_clip = name
        self.emit("clip", name=name)

    # ------------------------------------------------------------------ pose
    def set_pose(self, pose, joints=None):
        """Show ``pose`` (a :class:`Pose` or a (J, 10) snapshot) without an undo step, as
        playback and scrubbing do. ``joints`` hints which joints changed."""
        arr = pose.as_array() if hasattr(pose, "as_array") else np.asarray(pose, dtype=float)
        if arr.shape != (len(self.skeleton), 10):
            raise ValueError(f"expected a pose of {len(self.skeleton)} joints, got shape "
                             f"{arr.shape}")
        self.pose.set_array(arr)
        self.emit("pose", joints=joints)

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

    def _side_axis(self):
        """Index of the model axis that runs left-right: the one along which the rest
        positions of mirrored joint pairs differ most."""
        heads = self.skeleton.bind_matrices[:, :3, 3]
        pairs = np.flatnonzero(self.mirror != np.arange(len(self.mirror)))
        if len(pairs) == 0:
            return 0
        diff = np.abs(heads[pairs] - heads[self.mirror[pairs]]).sum(axis=0)
        return int(np.argmax(diff))

    # ------------------------------------------------------------------ rest pose and binding
    def rest_state(self):
        """What a bind-mode edit changes: (skeleton, binding, pose snapshot). The binding
        object itself is kept, so undo restores the weights bit for bit."""
        return (self.rig.skeleton, self.rig.binding, self.pose_snapshot())

    def make_rest_state(self, skeleton, indices, weights, pose=None):
        """A state for :meth:`push_rest_edit` from new weights (validated here)."""
        binding = SkinBinding(self.rig.vertices, indices, weights, len(skeleton))
        return (skeleton, binding, self.pose_snapshot() if pose is None else np.array(pose))

    def apply_rest_state(self, state):
        skeleton, binding, pose = state
        if len(skeleton) != len(self.skeleton) or binding.num_vertices != len(self.rig.vertices):
            raise ValueError("expected a rest state of this rig's joints and vertices")
        self.rig.skeleton = skeleton
        self.pose.skeleton = skeleton
        self.rig.binding = binding
        self.pose.set_array(pose)
        self.emit("rest")
        self.emit("pose", joints=None)

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


def mirror_pose(pose, mirror, names, axis, source="L"):
    """Copy one side's local transforms onto the other, reflected across the plane normal to
    model ``axis`` (in place).

    Reflecting across the plane normal to x maps a rotation quaternion (x, y, z, w) to
    (x, -y, -z, w) (the component along the normal keeps its sign, the others flip) and a
    translation's x to -x. This is exact when the two sides' parent frames are mirror images
    aligned with the model axes: the usual case, and always so for frames built from head
    positions (elk skeletons, the bundled characters).
    """
    flip = np.ones(3)
    flip[axis] = -1.0
    qflip = -flip  # quaternion vector part under a reflection: -(sign) of each axis
    for i, name in enumerate(names):
        j = mirror[i]
        if j == i or _side_of(name) != source:
            continue
        pose.translation[j] = pose.translation[i] * flip
        q = pose.rotation[i].copy()
        q[:3] *= qflip
        pose.rotation[j] = q
        pose.scale[j] = pose.scale[i]


def _side_of(name):
    """"L", "R" or None from a joint name."""
    m = mirror_name(name)
    if m is None:
        return None
    for left, right in _MIRROR_PAIRS:
        if (left in name and right in m) and not (right in name and left in m):
            return "L"
        if right in name and left in m:
            return "R"
    return None


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
