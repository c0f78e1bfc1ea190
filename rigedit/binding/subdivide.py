"""Subdividing a skinned mesh with its weights: bigger characters of the same shape.

Used to build the big meshes the speed benchmarks and the proxy tests need (a 500,000-triangle
character from the bundled quadruped) without shipping one: each triangle is split at its
centroid into three, so the surface (and its shading) stays exactly the same and each new
vertex takes the mean of its triangle's three weight rows, which is what linear interpolation
of the weights over the triangle gives there.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..model.skinning import top_k_influences

__all__ = ["subdivide_centroid"]


def subdivide_centroid(vertices, faces, indices, weights, num_joints, levels=1):
    """Split every triangle at its centroid into three, ``levels`` times.

    Parameters
    ----------
    vertices : (V, 3) float
    faces : (F, 3) int
    indices, weights : (V, K) int and float
        Skin influences, rows summing to 1.
    num_joints : int
    levels : int
        Each level triples the triangles and adds one vertex per triangle.

    Returns
    -------
    vertices : (V + F + 3F + ..., 3) float64
        The original vertices first, then one centroid per triangle of each level.
    faces : (F * 3**levels, 3) int64
        Same orientation as the input's.
    indices, weights : (V', K) int32 and float64
        The centroid's weights are the mean of its corners' (at most K influences kept, the
        largest, renormalised).
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    idx = np.array(indices, dtype=np.int32)
    w = np.asarray(weights, dtype=np.float64)
    k = idx.shape[1]
    for _ in range(levels):
        n, m = len(v), len(f)
        rows = np.repeat(np.arange(n), k)
        per_joint = sp.csr_matrix((w.ravel(), (rows, idx.ravel())), shape=(n, num_joints))
        # each centroid's row: the mean of its three corners' rows
        corners = sp.csr_matrix((np.full(3 * m, 1.0 / 3.0), (np.repeat(np.arange(m), 3),
                                 f.ravel())), shape=(m, n))
        mid_idx, mid_w = top_k_influences((corners @ per_joint).toarray(), k)
        centroid = v[f].mean(axis=1)
        c = n + np.arange(m)
        a, b, d = f[:, 0], f[:, 1], f[:, 2]
        f = np.concatenate([np.column_stack([a, b, c]), np.column_stack([b, d, c]),
                            np.column_stack([d, a, c])])
        v = np.concatenate([v, centroid])
        idx = np.concatenate([idx, mid_idx])   # top_k_influences gives int32
        w = np.concatenate([w, mid_w])
    return v, f, idx, w
