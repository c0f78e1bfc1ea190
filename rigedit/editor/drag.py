"""Joint drags: pose-mode IK drags, axis-constrained drags (the toolbar's axis or an arrow
handle), and edit-mode rest moves (re-bound on release by
:class:`~rigedit.ui.rebind.RestRebind`).

:class:`PoseDrag` is the editing command alone (a joint pulled towards points, one undo step
at the end), usable from a script; the :class:`DragController` drives it from the 3D view's
gizmos. The controller is built for each scene (a rig opened builds a new one) with what it
uses; it never reaches into the window.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.ik import drag_joint

__all__ = ["DragController", "DragSettings", "PoseDrag", "constrain"]


@dataclass
class DragSettings:
    """What the tool bar sets for drags (kept by the window across rigs).

    Attributes
    ----------
    axis : int or None
        Constraint axis (0, 1, 2: model X, Y, Z) or None for free dragging.
    chain_length : int
        IK chain length of a pose-mode drag (1: turn the parent only).
    """

    axis: int = None
    chain_length: int = 2


def constrain(start, center, axis):
    """``center`` (3,) projected onto the line through ``start`` along model axis ``axis``
    (0, 1, 2), or unchanged for ``axis`` None."""
    if axis is None:
        return center
    e = np.eye(3)[axis]
    return start + np.dot(center - start, e) * e


class PoseDrag:
    """A pose-mode drag of one joint as document edits: each :meth:`step` solves IK from the
    pose at the press (:func:`~rigedit.model.ik.drag_joint`: a root moves, another joint turns
    its chain) and shows the result; :meth:`end` makes the whole drag one undo step.

    Parameters
    ----------
    document : Document
        Its joint ``joint`` is selected and its pose remembered (``begin_drag``).
    joint : int or str
    chain_length : int
        IK chain length (1: turn the parent only).
    """

    def __init__(self, document, joint, chain_length=2):
        self.document = document
        self.joint = document.skeleton.joint_index(joint)
        self.chain_length = int(chain_length)
        document.select(self.joint)
        self.start = document.pose_snapshot()
        self.work = document.pose.copy()
        # IK starts each step from the pose at the press: its forward kinematics is computed
        # once here, so a step runs FK once (the view's, for the new pose), not twice
        self.start_model = document.rig.joint_matrices(self.work)
        document.begin_drag()

    def step(self, target):
        """Pull the joint towards ``target`` (3,) model space; the document shows the pose
        (PoseChanged), not yet an undo step."""
        d = self.document
        self.work.set_array(self.start)
        drag_joint(d.skeleton, self.work, self.joint, target, self.chain_length,
                   fk=lambda _pose: self.start_model)
        d.set_pose(self.work)

    def end(self, label=None):
        """Release: the drag becomes one undo step (none when the pose did not change)."""
        self.document.end_drag(label or f"Drag {self.document.skeleton.names[self.joint]}")

    def cancel(self):
        """Give up the drag: the pose at the press comes back."""
        self.document.cancel_drag()


class DragController:
    """Turns gizmo drags into document edits.

    In pose mode a drag poses the character (IK over ``settings.chain_length`` joints,
    :func:`~rigedit.model.ik.drag_joint`, or the root moved) from the pose at the press, and the release makes the whole drag one
    undo step; in edit mode it moves the joint's bone preview and the release hands the new
    rest position to ``move_rest``.

    Parameters
    ----------
    document : Document
        Pose, mode, selection and undo; the view follows its events.
    scene : RigScene
        Its ``joint_positions`` (where joints really are) and ``bones`` (the edit preview).
    gizmos : JointGizmos
        The spheres (the dragged one follows the constrained target; it snaps back on end).
    axes : AxisHandles
        Follow the joint in edit mode.
    settings : DragSettings
    move_rest : callable
        ``move_rest(j, head)`` at the end of an edit-mode drag that moved joint ``j``; returns
        None when the move was refused (the sphere then snaps back).
    status : callable
        ``status(text)`` shows a message.
    request_render : callable
        Asks for one repaint (outside a drag, where VTK does not render by itself).

    Attributes
    ----------
    drag : dict or None
        The drag under way: ``joint``, ``start`` (3,), ``axis``, ``ik`` (the
        :class:`PoseDrag` of a pose-mode drag, which holds the pose at the press), ``target``
        (3,) once moved, ``heads`` (J, 3) the rest heads shown by an edit-mode drag.
    """

    def __init__(self, document, scene, gizmos, axes, settings, move_rest, status,
                 request_render):
        self.document = document
        self.scene = scene
        self.gizmos = gizmos
        self.axes = axes
        self.settings = settings
        self.move_rest = move_rest
        self.status = status
        self.request_render = request_render
        self.drag = None

    @property
    def active(self):
        """Whether a drag is held."""
        return self.drag is not None

    # ------------------------------------------------------------------ sphere drags
    def start(self, j, axis=None):
        """A drag of joint ``j`` begins: constrained to ``axis`` (an arrow handle's) or to
        the toolbar's axis."""
        d = self.document
        d.select(j)
        self.drag = {"joint": j, "start": self.gizmos.center(j),
                     "axis": self.settings.axis if axis is None else axis}
        if d.mode == "pose":
            self.drag["ik"] = PoseDrag(d, j, self.settings.chain_length)

    def move(self, j, center):
        """The dragged sphere is at ``center`` (3,)."""
        drag = self.drag
        if drag is None or drag["joint"] != j:
            return
        target = constrain(drag["start"], center, drag["axis"])
        if drag["axis"] is not None:
            self.gizmos.set_center(j, target)
        drag["target"] = target
        if "ik" in drag:
            self.step(j, target)
        else:
            heads = drag.get("heads")
            if heads is None:   # the rest pose holds still during the drag: once per drag
                rig = self.document.rig
                heads = rig.joint_matrices(rig.rest_pose())[:, :3, 3].copy()
                drag["heads"] = heads
            heads[j] = target
            self.scene.bones.points[:] = heads
            self.scene.bones.Modified()
            self.axes.set_position(target)

    def step(self, j, target):
        """One pose-mode drag step (:meth:`PoseDrag.step`; its event updates the view's
        points in place; no render). The tool bar's chain length is read at each step."""
        ik = self.drag["ik"]
        ik.chain_length = self.settings.chain_length
        ik.step(target)

    def end(self, j):
        """The drag of joint ``j`` ends: one undo step (pose mode) or a rest move."""
        drag, self.drag = self.drag, None
        if drag is None:
            return
        d = self.document
        name = d.skeleton.names[j]
        if "ik" in drag:
            drag["ik"].end(f"Drag {name}")
            # Snap the sphere onto where the joint really is (it may not reach the mouse).
            self.gizmos.set_center(j, self.scene.joint_positions[j])
            self.status(f"Posed {name}")
        elif "target" in drag and not np.allclose(drag["target"], drag["start"]):
            if self.move_rest(j, drag["target"]) is None:
                self.gizmos.set_center(j, self.scene.joint_positions[j])
        self.request_render()

    # ------------------------------------------------------------------ arrow handles
    # An arrow handle drag: the selected joint, constrained to the arrow's axis.
    def axis_start(self, axis):
        j = self.document.selection
        if j is not None:
            self.start(j, axis=axis)

    def axis_move(self, axis, target):
        if self.drag is not None:
            self.move(self.drag["joint"], target)

    def axis_end(self, axis):
        if self.drag is not None:
            self.end(self.drag["joint"])
