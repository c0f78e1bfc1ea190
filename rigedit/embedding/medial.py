"""Spheres on the approximate medial surface, packed largest first (Pinocchio section 3).

A cell lies on the medial surface where the distance field's gradient is discontinuous:
its direction to the nearest surface point and a neighbour's differ by a wide angle (the
two cells see opposite or distant sides of the part they are in). Those cells, deepest
first, become sphere centres; a candidate is dropped when an already chosen sphere contains
it, so big parts get a few big spheres and limbs a string of small ones down their middle.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["medial_cells", "pack_spheres"]

#: Neighbouring gradients more than this far apart (about 65 degrees) mark the medial
#: surface; a smooth side of a part turns its gradient by only ~h / radius per cell.
MEDIAL_COS = 0.42
#: Cells shallower than this many cell sizes are skipped: their nearest point is noisy.
MIN_DEPTH_CELLS = 0.9
#: A medial cell's two nearest surface points (its own and a neighbour's) must be at least
#: this fraction of its depth apart (the lambda-medial axis of Chazal and Lieutier): this
#: prunes the medial branches that run into every small bump and crease of the surface,
#: which would draw the search off the middle of the body, and keeps the axis of any part
#: whose two sides are both in view (a limb: 2 depths apart).
SEPARATION = 1.0


def medial_cells(field):
    """Cells of ``field`` on the approximate medial surface.

    Parameters
    ----------
    field : DistanceField

    Returns
    -------
    centres : (M, 3) float64
        Cell centres.
    radii : (M,) float64
        Their depth (distance to the surface).
    """
    depth, h = field.depth, field.h
    deep = field.inside & (depth > MIN_DEPTH_CELLS * h)
    if not deep.any():
        return np.zeros((0, 3)), np.zeros(0)
    # work on the box around the deep cells, with whole-array shifts per neighbour direction
    box = tuple(slice(lo, hi + 1) for lo, hi in zip(np.argwhere(deep).min(0),
                                                     np.argwhere(deep).max(0)))
    deep = deep[box]
    dep = np.where(deep, depth[box], 0.0)
    near = np.where(deep[..., None], field.nearest[box], 0.0)
    grid = np.stack(np.meshgrid(*[np.arange(b.start, b.stop) for b in box], indexing="ij"), -1)
    grad = field.origin + grid * h - near
    grad /= np.maximum(np.linalg.norm(grad, axis=-1, keepdims=True), 1e-300)
    medial = np.zeros(deep.shape, dtype=bool)

    def cut(step, first):
        return tuple(slice(None) if d == 0 else (slice(0, -1) if (d > 0) == first
                                                 else slice(1, None)) for d in step)

    for step in ((1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (1, -1, 0), (1, 0, 1),
                 (1, 0, -1), (0, 1, 1), (0, 1, -1)):
        a, b = cut(step, True), cut(step, False)
        both = deep[a] & deep[b]
        cos = np.einsum("...k,...k->...", grad[a], grad[b])
        apart = np.linalg.norm(near[a] - near[b], axis=-1)
        jump = both & (cos < MEDIAL_COS)
        medial[a] |= jump & (apart > SEPARATION * dep[a])
        medial[b] |= jump & (apart > SEPARATION * dep[b])
    cells = np.argwhere(medial) + np.array([b.start for b in box])
    return field.points(cells), depth[tuple(cells.T)]


#: A candidate is dropped when it lies within this fraction of a chosen sphere's radius of
#: its centre. Pinocchio drops those inside the sphere (1.0); that leaves a thick trunk
#: with one or two vertices, too few for a hip, a chest and shoulders to find distinct
#: places, so we pack twice as densely.
PACK = 0.5
MAX_SPHERES = 1200


def pack_spheres(centres, radii, min_radius=0.0, max_count=None):
    """Greedy packing: deepest candidate first, skipping any inside a chosen sphere.

    Parameters
    ----------
    centres : (M, 3) float64
    radii : (M,) float64
    min_radius : float
        Candidates shallower than this are ignored.
    max_count : int, optional
        At most this many spheres (default ``MAX_SPHERES``): the packing loosens until they
        fit. The search's cost matrices grow with the square of the count; flat, boxy
        parts (a low-polygon figure) have broad medial sheets that would fill it.

    Returns
    -------
    centres : (S, 3) float64
    radii : (S,) float64
        Chosen spheres, largest first.
    """
    keep = radii >= min_radius
    centres, radii = centres[keep], radii[keep]
    order = np.argsort(-radii, kind="stable")
    centres, radii = centres[order], radii[order]
    max_count = MAX_SPHERES if max_count is None else max_count
    tree = cKDTree(centres)
    pack = PACK
    while True:
        alive = np.ones(len(centres), dtype=bool)
        chosen = []
        for i in range(len(centres)):
            if not alive[i]:
                continue
            chosen.append(i)
            alive[tree.query_ball_point(centres[i], pack * radii[i])] = False
        if len(chosen) <= max_count or pack > 4.0:
            break
        pack *= 1.4
    chosen = np.asarray(chosen[:max_count], dtype=np.int64)
    return centres[chosen], radii[chosen]
