"""Skinning weights from the modelling primitives, with regions that must not mix."""
from __future__ import annotations

import numpy as np


def primitive_weights(vertices, prims, names, regions, max_influences=4, offset=0.03,
                      power=4.0, min_weight=0.02):
    """Top-K weights from the distance of each vertex to each joint's primitives.

    Parameters
    ----------
    vertices : (V, 3)
    prims : list of Prim (each with ``owner``, a joint name)
    names : list[str] joint names (skeleton order)
    regions : dict joint name -> region name; joints of region ``"core"`` may mix with any
        one region, joints of any other region never mix with another non-core region.
    offset : float
        Metres added to the surface distance; larger spreads influences further.

    Returns
    -------
    indices (V, K) int32, weights (V, K) float64 (rows sum to 1)
    """
    index = {n: i for i, n in enumerate(names)}
    J = len(names)
    d = np.full((len(vertices), J), np.inf)
    for p in prims:
        j = index[p.owner]
        d[:, j] = np.minimum(d[:, j], p.sdf(vertices))
    d = np.maximum(d, 0.0)
    region_names = sorted(set(regions.values()) - {"core"})
    reg_of_joint = np.array([regions.get(n, "core") for n in names])
    # Region of a vertex: that of its nearest joint; a core vertex takes the region of its
    # nearest non-core joint as the only one it may mix with.
    nearest = np.argmin(d, axis=1)
    vreg = reg_of_joint[nearest]
    noncore = reg_of_joint != "core"
    dn = np.where(noncore[None, :], d, np.inf)
    near_region = reg_of_joint[np.argmin(dn, axis=1)]
    allowed_region = np.where(vreg == "core", near_region, vreg)
    w = 1.0 / (d + offset) ** power
    for r in region_names:
        cols = reg_of_joint == r
        mask = allowed_region != r
        w[np.ix_(mask, cols)] = 0.0
    w[np.isinf(d)] = 0.0
    k = max_influences
    idx = np.argsort(-w, axis=1)[:, :k]
    val = np.take_along_axis(w, idx, axis=1)
    val /= val.sum(axis=1, keepdims=True)
    val[val < min_weight] = 0.0
    val /= val.sum(axis=1, keepdims=True)
    return idx.astype(np.int32), val
