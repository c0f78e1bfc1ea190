"""File > Re-embed around the joints I moved: after an auto-rig, the joints the user dragged in
bind mode are pinned (hints) and the embedding runs again for the others.

The joints moved are those whose rest position left where the auto-rig (or the last re-embed)
put them (``rig.autorig_report.embedded``; a rest move keeps the other joints' positions), and
those pinned by the last re-embed stay pinned where they are now. The work runs off the UI
thread through :class:`~rigedit.ui.jobs.JobRunner` (progress bar, Cancel), as File > Auto-rig
mesh does:
:func:`rigedit.autorig` on the character's own mesh (already standing +Y up, facing +Z) with
the same template, weights method and clips. The result replaces the character as a new
auto-rig does (name, folder and texture kept; the undo history starts again: the skeleton,
weights and clips are all new), in bind mode. Edits made while it runs drop the result with a
status message rather than lose them.
"""
from __future__ import annotations

import numpy as np

from ..editor.autorig import reembed_mesh
from .menus import make_action

__all__ = ["ReembedAction", "moved_joints", "MOVED"]

#: A joint counts as moved when its rest position is this fraction of the skeleton's size
#: from where the embedding put it (a drag moves it by far more; rebuilding the frames
#: leaves ~1e-12).
MOVED = 1e-4


def moved_joints(skeleton, report):
    """Joints to pin: moved since the embedding, or pinned by it, at their rest positions.

    Parameters
    ----------
    skeleton : Skeleton
        The character's skeleton now.
    report : AutorigReport
        ``rig.autorig_report`` (``embedded``: (J, 3) joints as embedded; ``hints``).

    Returns
    -------
    dict[str, (3,) float64]
        Joint name -> its rest position now, in the rig's coordinates (what
        :func:`rigedit.autorig` takes as ``hints`` for the rig's own mesh).

    Raises
    ------
    ValueError
        When the rig was not auto-rigged, or its joints are no longer the template's.
    """
    embedded = getattr(report, "embedded", None)
    if embedded is None:
        raise ValueError("this character was not auto-rigged here (use File > Auto-rig mesh "
                         "first)")
    if len(embedded) != len(skeleton):
        raise ValueError(f"the skeleton has {len(skeleton)} joints, the auto-rig made "
                         f"{len(embedded)}: re-embedding needs the template's joints")
    rest = skeleton.forward(skeleton.rest_local_matrices())[:, :3, 3]
    size = float(np.linalg.norm(np.ptp(embedded, axis=0))) or 1.0
    moved = np.linalg.norm(rest - embedded, axis=1) > MOVED * size
    names = [n for n, m in zip(skeleton.names, moved) if m]
    names += [n for n in getattr(report, "hints", {}) if n in skeleton.index and n not in names]
    return {n: rest[skeleton.index[n]].copy() for n in names}


class ReembedAction:
    """File > Re-embed around the joints I moved.

    Parameters
    ----------
    document : Document
    services : Services
    """

    LABEL = "Re-embedding"

    def __init__(self, document, services):
        self.document = document
        self.services = services

    def actions(self):
        """name -> QAction for :func:`.menus.build_menus`."""
        return {"reembed": make_action(
            self.services.parent, "Re-embed around the joints I moved", self.run,
            tip="After an auto-rig: pin the joints dragged in bind mode and place the others "
                "again around them")}

    def run(self, *_):
        """Start the re-embedding; returns the job, or None (with a status message) when
        there is nothing to do or another job runs."""
        doc, status, job = self.document, self.services.status, self.services.jobs.job
        rig = doc.rig
        report = rig.meta.autorig_report
        try:
            hints = moved_joints(doc.skeleton, report)
        except ValueError as exc:
            status(f"Re-embed: {exc}")
            return None
        if not hints:
            status("Re-embed: no joint moved since the auto-rig; in bind mode drag the "
                     "joints that are wrong, then re-embed around them")
            return None
        if job is not None:
            status(f"Busy with '{job.label}': re-embed when it is done")
            return None
        top = doc.undo_stack.top
        template, weights = report.template, rig.weights_method or "heat"
        clips = bool(report.clips)
        vertices, faces = rig.vertices.copy(), rig.faces.copy()
        label = f"{self.LABEL} {rig.name or 'the character'} around {len(hints)} joints"

        def work(progress):
            return reembed_mesh(vertices, faces, template, weights, clips, hints, progress)

        return self.services.run_job(label, work,
                                     lambda new: self._done(rig, top, new, sorted(hints)))

    def _done(self, rig, top, new, pinned):
        doc, status = self.document, self.services.status
        if doc.rig is not rig or doc.undo_stack.top is not top:
            status("Re-embed dropped: the character changed while it ran; re-embed again")
            return None
        new.name, new.path = rig.name, rig.path
        if getattr(rig, "surface", None) is not None and len(new.vertices) == len(rig.vertices):
            new.surface = rig.surface   # same vertices in the same order: the texture holds
        new.autorig_report.source = rig.autorig_report.source
        doc.set_rig(new, modified=True)
        self.document.set_mode("edit")   # the window follows the mode event
        shown = ", ".join(pinned[:6]) + (f" and {len(pinned) - 6} more" if len(pinned) > 6
                                         else "")
        status(f"Re-embedded around {shown}; the other joints placed again "
                 f"(cost {new.autorig_report.cost:.3g})")
        return new
