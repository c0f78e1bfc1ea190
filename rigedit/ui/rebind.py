"""Edit-mode rest moves: a joint's rest position moved, the skin re-bound in a worker, and
Undo cancelling a re-bind still running when it is the latest edit."""
from __future__ import annotations

from PyQt5 import QtCore

from ..editor.document import skeleton_with_moved_joint
from ..editor.recompute import compute_weights_for

__all__ = ["RestRebind"]


class RestRebind:
    """Moves rest positions and re-binds the skin off the UI thread.

    Parameters
    ----------
    document : Document
    run_job : callable
        ``run_job(label, fn, done, cancelled)`` -> Job or None (see
        :meth:`~rigedit.ui.jobs.JobRunner.run`).
    current_job : callable
        ``current_job()`` -> the Job running now, or None.
    refresh_view : callable
        ``refresh_view()`` shows the document's pose again (bones and spheres included) and
        asks for a repaint.
    status : callable
        ``status(text)``.
    held : callable
        ``held()`` is True while the user holds a gizmo drag or a slider.
    undo_changed : callable
        Called when what Undo would do changed (a re-bind started).

    Attributes
    ----------
    pending : tuple or None
        ``(job, undo-stack top at its start, label)`` of the running re-bind.
    """

    def __init__(self, document, run_job, current_job, refresh_view, status, held,
                 undo_changed):
        self.document = document
        self.run_job = run_job
        self.current_job = current_job
        self.refresh_view = refresh_view
        self.status = status
        self.held = held
        self.undo_changed = undo_changed
        self.pending = None

    def move_joint(self, j, head):
        """Move joint ``j``'s rest position to ``head`` and re-bind the skin in a worker.

        Returns the :class:`Job`, or None when another job runs (a second rest move is
        refused with a status message, and the view goes back to the rest position).

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
        busy = self.current_job()
        if busy is not None:
            self.refresh_view()  # the dragged bone goes back to the rest position
            self.status(f"Busy with '{busy.label}': {name} keeps its rest position; wait "
                        f"for it to finish or cancel it, then move the joint again")
            return None
        rig, base_skeleton, base_binding = d.rig, d.skeleton, d.rig.binding
        skeleton = skeleton_with_moved_joint(base_skeleton, j, head)
        vertices = rig.vertices
        label = f"Move {name} (rest)"

        def done(result):
            self.pending = None
            if job.is_cancelled:  # undo cancelled it after the result was on its way
                cancelled()
                return
            if self.held() or d.dragging:
                # A pose drag or a slider is held: its undo step starts from the pose under
                # the old rest, so the rest edit waits for it to end.
                QtCore.QTimer.singleShot(50, lambda: done(result))
                return
            if d.rig is not rig or d.skeleton is not base_skeleton \
                    or d.rig.binding is not base_binding:
                what = "another rig was opened" if d.rig is not rig else \
                    "the skeleton or the weights changed"
                self.refresh_view()
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
            self.pending = None
            self.refresh_view()
            self.status(f"Re-bind cancelled; {name} keeps its rest position")

        job = self.run_job(f"Re-binding after moving {name}",
                           lambda report: compute_weights_for(vertices, skeleton,
                                                              progress=report,
                                                              faces=rig.faces),
                           done, cancelled)
        # Where the move sits in the history: undo from here cancels it.
        self.pending = (job, d.undo_stack.top, label) if job is not None else None
        self.undo_changed()
        return job

    def undoable(self):
        """The pending re-bind ``(job, top, label)`` when undo would cancel it (it still runs
        and nothing was done since it started), else None."""
        pending = self.pending
        if pending is not None and pending[0] is self.current_job() and \
                self.document.undo_stack.top is pending[1]:
            return pending
        return None

    def undo(self):
        """Undo: cancels a running re-bind when it is the latest edit (returns None), else
        undoes the document's last step."""
        pending = self.undoable()
        if pending is not None:
            self.pending = None
            pending[0].cancel()
            self.status(f"Undo {pending[2]}: re-bind cancelled")
            return None
        return self.document.undo()
