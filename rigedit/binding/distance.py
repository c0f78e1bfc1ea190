"""Distances of points to bones, and the inverse-distance weighting rule built on them.

Shared by the inverse-distance weights (:mod:`rigedit.binding.weights`) and the heat weights
(:mod:`rigedit.binding.heat`, which falls back on them), so that neither imports the other.
"""
from __future__ import annotations

import numpy as np

from ..model.skinning import top_k_influences

__all__ = ["point_segment_distance", "inverse_distance_weights"]


def point_segment_distance(points, starts, ends, out=None):
    """Euclidean distance of every point to every segment.

    Parameters
    ----------
    points : (N, 3) float
    starts, ends : (S, 3) float
        Segment end points; a zero-length segment is a point.

    Returns
    -------
    dist : (N, S) float64
    """
    points = np.asarray(points, dtype=np.float64)
    starts = np.asarray(starts, dtype=np.float64)
    seg = np.asarray(ends, dtype=np.float64) - starts          # (S, 3)
    seg_len2 = np.einsum("sd,sd->s", seg, seg)
    inv_len2 = np.where(seg_len2 > 1e-24, 1.0 / np.maximum(seg_len2, 1e-24), 0.0)
    # Expanded form |p - s - t·seg|^2 = |p - s|^2 - 2 t a + t^2 L2 with a = (p - s)·seg, built
    # from two (N, 3) x (3, S) products and in-place updates: no (N, S, 3) temporary.
    a = points @ seg.T
    a -= np.einsum("sd,sd->s", starts, seg)
    t = a * inv_len2
    np.clip(t, 0.0, 1.0, out=t)
    d2 = points @ (-2.0 * starts.T)
    d2 += np.einsum("nd,nd->n", points, points)[:, None]
    d2 += np.einsum("sd,sd->s", starts, starts)
    a *= 2.0
    a -= t * seg_len2
    a *= t
    d2 -= a
    np.maximum(d2, 0.0, out=d2)  # rounding can leave tiny negatives
    return np.sqrt(d2, out=d2)


def inverse_distance_weights(dist, k, power=4.0, eps=1e-6):
    """The inverse-distance rule: weight ``1 / ((d_j / d_min)^p + eps)``, ``k`` largest kept.

    Parameters
    ----------
    dist : (N, J) float64
        Distance of each point to each joint (overwritten: divided by each row's minimum).
    k : int
    power, eps : float
        As in :func:`idw_weights`.

    Returns
    -------
    indices : (N, k) int32
        Columns of ``dist``.
    weights : (N, k) float64, rows sum to 1
    """
    dist /= np.maximum(dist.min(axis=1, keepdims=True), 1e-12)
    d2 = dist * dist
    w = 1.0 / (d2 ** (power / 2.0) + eps) if power != 4 else 1.0 / (np.square(d2) + eps)
    return top_k_influences(w, k)
