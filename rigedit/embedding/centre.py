"""The middle of a part: where a joint sits across its bone.

An artist puts a joint in the middle of the limb it moves, whatever the limb's shape in
cross-section. :func:`centre_joints` finds that middle in the plane across the bone: the
depth-weighted centroid of the deepest points of the cross-section near the joint (its
maximal inscribed disc), which is the medial axis of a limb and the centre of a trunk.
"""
from __future__ import annotations

import numpy as np

from ..model.transforms import tangents

__all__ = ["centre_joints"]


def centre_joints(field, points, directions, reach=1.5):
    """Move each point to the middle of the mesh's cross-section across its direction.

    Parameters
    ----------
    field : DistanceField
    points : (N, 3) float64
    directions : (N, 3) float64
        The bone direction at each point (the cross-section is perpendicular to it).
    reach : float
        Radius of the searched disc, in multiples of the point's depth (plus two cells).

    Returns
    -------
    (N, 3) float64
        Points moved to the depth-weighted centroid of the deepest fifth of their disc's
        depth range; points outside the mesh are left as they are.
    """
    h = field.h
    out = np.array(points, dtype=np.float64)
    depth = field(out)
    for i in range(len(out)):
        length = np.linalg.norm(directions[i])
        if depth[i] <= 0 or not np.isfinite(length) or length < 1e-12:
            continue
        d = directions[i] / length
        e1, e2 = tangents(d)
        radius = reach * depth[i] + 2 * h
        t = np.arange(-radius, radius + 1e-12, 0.5 * h)
        u, v = np.meshgrid(t, t)
        disc = (u * u + v * v) <= radius * radius
        pts = out[i] + u[disc][:, None] * e1 + v[disc][:, None] * e2
        dep = field(pts)
        top = dep.max()
        if top <= 0:
            continue
        keep = dep >= 0.8 * top
        out[i] = np.average(pts[keep], axis=0, weights=dep[keep])
    return out
