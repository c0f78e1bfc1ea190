"""Recompute the skin weights: a slow half that can run in a worker, and a quick half that
makes the result one undo step.

The slow half is :func:`rigedit.binding.compute_weights` on what the document held when the
job was made; it takes a progress callable (:mod:`rigedit.progress`: ``progress(fraction,
stage)``, and raising :class:`~rigedit.progress.Cancelled` stops it). The quick half refuses
weights made for another rig or skeleton (one opened, or a rest edit undone, meanwhile).
"""
from __future__ import annotations

from ..binding import compute_weights, default_method

__all__ = ["RecomputeWeights", "recompute_weights", "compute_weights_for"]


def compute_weights_for(vertices, skeleton, method=None, progress=None, faces=None):
    """Skin weights of ``vertices`` for ``skeleton`` (the slow work of a recompute, an
    edit-mode re-bind or a mesh opened with a skeleton; safe in a worker thread).

    Parameters
    ----------
    vertices : (V, 3) float64
    skeleton : Skeleton
    method : {"heat", "idw"}, optional
        Bone heat for a mesh with ``faces``, inverse distance for a point cloud, by default.
    progress : callable, optional
        ``progress(fraction, stage=None)`` (:mod:`rigedit.progress`); its
        :class:`~rigedit.progress.Cancelled` stops the work.
    faces : (F, 3) int, optional

    Returns
    -------
    indices : (V, K) int32
    weights : (V, K) float64
    """
    method = method or default_method(faces)
    return compute_weights(vertices, skeleton, method, progress=progress, faces=faces)


class RecomputeWeights:
    """One recomputation of the document's weights.

    Parameters
    ----------
    document : Document
    method : {"heat", "idw"}, optional
        Bone heat for a mesh with faces, inverse distance for a point cloud, by default.

    Attributes
    ----------
    method : str
    rig, skeleton :
        What the weights are computed for (the document's when the job was made).
    """

    def __init__(self, document, method=None):
        self.document = document
        self.rig = document.rig
        self.skeleton = document.skeleton
        self.method = method or default_method(self.rig.faces)

    def compute(self, progress=None):
        """The slow half (safe in a worker thread: it reads only what was captured).

        Returns
        -------
        indices : (V, K) int32
        weights : (V, K) float64
        """
        def relay(fraction, stage=None):   # compute_weights may give the fraction alone
            if progress is not None:
                progress(fraction, stage or self.method)

        return compute_weights_for(self.rig.vertices, self.skeleton, self.method,
                                   progress=relay, faces=self.rig.faces)

    def apply(self, result):
        """Make ``result`` (from :meth:`compute`) the weights, as one undo step.

        Returns
        -------
        message : str
            What happened, for the status bar.
        applied : bool
            False when the document moved on (the result would not fit it).
        """
        d = self.document
        if d.rig is not self.rig or d.skeleton is not self.skeleton:
            what = "another rig was opened" if d.rig is not self.rig else "the skeleton changed"
            return (f"Recomputed weights dropped: {what} while they were computed; "
                    f"recompute them again"), False
        indices, weights = result
        d.set_weights(indices, weights, label="Recompute weights")
        return f"Recomputed weights for {len(self.rig.vertices):,} vertices", True


def recompute_weights(document, method=None, progress=None):
    """Recompute the weights now (both halves), as one undo step. Returns the message."""
    job = RecomputeWeights(document, method)
    return job.apply(job.compute(progress))[0]
