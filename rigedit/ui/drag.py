"""Gizmo drags of the editor window: pose-mode IK drags, axis-constrained drags and
edit-mode rest moves that re-bind the skin in a worker.

A mixin of :class:`~rigedit.ui.main_window.MainWindow` (split out to keep modules small); it
uses the window's ``document``, ``gizmos``, ``axes``, ``scene``, ``mode``, ``axis``,
``chain_length``, ``run_job``, ``status`` and ``request_render``.
"""
from __future__ import annotations

import numpy as np
from PyQt5 import QtCore

from ..document import skeleton_with_moved_joint
from ..model.ik import drag_joint
from .jobs import weights_in_chunks

__all__ = ["DragMixin"]


class DragMixin:
    """Sphere and arrow-handle drags for :class:`MainWindow`."""

    # ================================================================== gizmo drags
    def _drag_start(self, j, axis=None):
        """A drag of joint ``j`` begins: constrained to ``axis`` (an arrow handle's) or to
        the toolbar's axis."""
        d = self.document
        d.select(j)
        self._interacting = True
        self._drag = {"joint": j, "start": self.gizmos.center(j),
                      "axis": self.axis if axis is None else axis,
                      "pose": d.pose_snapshot(), "work": d.pose.copy()}
        if self.mode == "pose":
            d.begin_drag()

    @staticmethod
    def _constrain(start, center, axis):
        if axis is None:
            return center
        e = np.eye(3)[axis]
        return start + np.dot(center - start, e) * e

    def _drag_move(self, j, center):
        drag = self._drag
        if drag is None or drag["joint"] != j:
            return
        target = self._constrain(drag["start"], center, drag["axis"])
        if drag["axis"] is not None:
            self.gizmos.set_center(j, target)
        drag["target"] = target
        if self.mode == "pose":
            self.drag_step(j, target)
        else:
            rest = self.document.rig.joint_matrices(self.document.rig.rest_pose())
            heads = rest[:, :3, 3].copy()
            heads[j] = target
            self.scene.bones.points[:] = heads
            self.scene.bones.Modified()
            self.axes.set_position(target)

    def drag_step(self, j, target):
        """One pose-mode drag step: IK from the pose at drag start, then FK, skinning and the
        actors' points updated in place (no render; the caller or VTK renders)."""
        work = self._drag["work"]
        work.set_array(self._drag["pose"])
        drag_joint(self.document.skeleton, work, j, target, self.chain_length,
                   fk=self.document.rig.joint_matrices)
        self.document.set_pose(work)

    def _drag_end(self, j):
        drag, self._drag = self._drag, None
        self._interacting = False
        if drag is None:
            return
        d = self.document
        name = d.skeleton.names[j]
        if self.mode == "pose":
            d.end_drag(f"Drag {name}")
            # Snap the sphere onto where the joint really is (it may not reach the mouse).
            self.gizmos.set_center(j, self.scene.joint_positions[j])
            self.status(f"Posed {name}")
        elif "target" in drag and not np.allclose(drag["target"], drag["start"]):
            self.rebind_moved_joint(j, drag["target"])
        self.request_render()

    # An arrow handle drag: the selected joint, constrained to the arrow's axis.
    def _axis_drag_start(self, axis):
        j = self.document.selection
        if j is not None:
            self._drag_start(j, axis=axis)

    def _axis_drag_move(self, axis, target):
        if self._drag is not None:
            self._drag_move(self._drag["joint"], target)

    def _axis_drag_end(self, axis):
        if self._drag is not None:
            self._drag_end(self._drag["joint"])

    # ================================================================== bind mode
    def rebind_moved_joint(self, j, head):
        """Move joint ``j``'s rest position to ``head`` and re-bind the skin in a worker.

        Returns the :class:`Job`, or None when another job runs (a second rest move is
        refused with a status message, and the view snaps back).

        While it runs the user may keep posing: the finished re-bind keeps the pose the
        document has then (offset by the rest change), not the one it started from, and
        waits for a drag still held to end. Undo
        pressed before any newer edit cancels it (the rest move was the last thing done).
        A result whose rig, skeleton or weights were replaced meanwhile (another rig opened,
        a rest edit redone, weights loaded) is dropped with a status message rather than
        applied to data it was not computed for.
        """
        d = self.document
        name = d.skeleton.names[j]
        if self.job is not None:
            self._refresh_pose()  # the dragged bone and sphere go back to the rest position
            self.gizmos.set_center(j, self.scene.joint_positions[j])
            self.request_render()
            self.status(f"Busy with '{self.job.label}': {name} keeps its rest position; wait "
                        f"for it to finish or cancel it, then move the joint again")
            return None
        rig, base_skeleton, base_binding = d.rig, d.skeleton, d.rig.binding
        skeleton = skeleton_with_moved_joint(base_skeleton, j, head)
        vertices = rig.vertices
        label = f"Move {name} (rest)"

        def done(result):
            self._pending_rebind = None
            if job.is_cancelled:  # undo cancelled it after the result was on its way
                cancelled()
                return
            if self._interacting or d.dragging:
                # A pose drag or a slider is held: its undo step starts from the pose under
                # the old rest, so the rest edit waits for it to end.
                QtCore.QTimer.singleShot(50, lambda: done(result))
                return
            if d.rig is not rig or d.skeleton is not base_skeleton \
                    or d.rig.binding is not base_binding:
                what = "another rig was opened" if d.rig is not rig else \
                    "the skeleton or the weights changed"
                self._refresh_pose()
                self.status(f"Re-bind after moving {name} dropped: {what} while it ran; "
                            f"move the joint again")
                return
            indices, weights = result
            before = d.rest_state()  # the pose now, with any edit made while it ran
            pose = before[2].copy()
            pose[:, :3] += skeleton.rest_translation - base_skeleton.rest_translation
            d.push_rest_edit(label, before, d.make_rest_state(skeleton, indices, weights, pose))
            self.status(f"Moved {name}'s rest position and re-bound the skin "
                        f"({len(vertices):,} vertices)")

        def cancelled():
            self._pending_rebind = None
            self._refresh_pose()
            self.request_render()
            self.status(f"Re-bind cancelled; {name} keeps its rest position")

        job = self.run_job(f"Re-binding after moving {name}",
                           lambda report: weights_in_chunks(vertices, skeleton, report=report,
                                                            faces=rig.faces),
                           done, cancelled)
        # Where the move sits in the history: undo from here cancels it.
        self._pending_rebind = (job, d.undo_stack.top, label) if job is not None else None
        self._update_undo_actions()
        return job

    def _undoable_rebind(self):
        """The pending re-bind ``(job, top, label)`` when undo would cancel it (it still runs
        and nothing was done since it started), else None."""
        pending = self._pending_rebind
        if pending is not None and pending[0] is self.job and \
                self.document.undo_stack.top is pending[1]:
            return pending
        return None

    def undo(self):
        """Edit > Undo: cancels a running re-bind when it is the latest edit, else undoes the
        document's last step."""
        pending = self._undoable_rebind()
        if pending is not None:
            self._pending_rebind = None
            self.job.cancel()
            self.status(f"Undo {pending[2]}: re-bind cancelled")
            return None
        return self.document.undo()
