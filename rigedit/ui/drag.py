"""Gizmo drags of the editor window: pose-mode IK drags, axis-constrained drags and
edit-mode rest moves that re-bind the skin in a worker.

A mixin of :class:`~rigedit.ui.main_window.MainWindow` (split out to keep modules small); it
uses the window's ``document``, ``gizmos``, ``axes``, ``scene``, ``mode``, ``axis``,
``chain_length``, ``run_job``, ``status`` and ``request_render``.
"""
from __future__ import annotations

import numpy as np

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
        if self.job is not None:
            self.status("Busy: wait for the current job or cancel it")
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
        """Move joint ``j``'s rest position to ``head`` and re-bind the skin in a worker."""
        d = self.document
        before = d.rest_state()
        skeleton = skeleton_with_moved_joint(d.skeleton, j, head)
        vertices = d.rig.vertices
        name = d.skeleton.names[j]

        def done(result):
            indices, weights = result
            pose = before[2].copy()
            delta = skeleton.rest_translation - before[0].rest_translation
            pose[:, :3] += delta  # keep the pose's offsets from rest
            d.push_rest_edit(f"Move {name} (rest)", before,
                             d.make_rest_state(skeleton, indices, weights, pose))
            self.status(f"Moved {name}'s rest position and re-bound the skin "
                        f"({len(vertices):,} vertices)")

        def cancelled():
            self._refresh_pose()
            self.request_render()
            self.status(f"Re-bind cancelled; {name} keeps its rest position")

        self.run_job(f"Re-binding after moving {name}",
                     lambda report: weights_in_chunks(vertices, skeleton, report=report),
                     done, cancelled)
