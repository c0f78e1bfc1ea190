"""Ray maths of the 3D view: display <-> world points, the mouse ray, ray-sphere picking.

Never imports Qt. The display functions take a ``vtkRenderer``; the picking functions are
plain numpy on points (N, 3), so they are tested without a window.
"""
from __future__ import annotations

import numpy as np

__all__ = ["world_to_display", "display_to_world", "mouse_ray", "pixel_spacing",
           "sphere_entries", "pick_sphere", "closest_on_line"]


def world_to_display(renderer, world):
    """(3,) display coordinates (pixels x, y and depth) of a world point in ``renderer``."""
    renderer.SetWorldPoint(*np.asarray(world, dtype=float), 1.0)
    renderer.WorldToDisplay()
    return np.array(renderer.GetDisplayPoint())


def display_to_world(renderer, x, y, z):
    """(3,) world point at display pixel (x, y) and depth ``z`` (0 near plane, 1 far) in
    ``renderer``: the inverse of :func:`world_to_display`."""
    renderer.SetDisplayPoint(float(x), float(y), float(z))
    renderer.DisplayToWorld()
    w = np.array(renderer.GetWorldPoint())
    return w[:3] / w[3]


def mouse_ray(renderer, x, y):
    """The ray through display pixel (x, y): origin on the near plane and unit direction, in
    world coordinates (perspective or parallel camera alike).

    Returns
    -------
    origin, direction : (3,) float64
    """
    near = display_to_world(renderer, x, y, 0.0)
    d = display_to_world(renderer, x, y, 1.0) - near
    return near, d / np.linalg.norm(d)


def pixel_spacing(renderer, x, y):
    """How far apart, in world units, the rays through (x, y) and (x + 1, y) are, as a
    function of the distance ``t`` along the ray: ``a + t * b`` (``b`` is 0 for a parallel
    camera). Used to give small spheres a minimum size on screen for picking.

    Returns
    -------
    offset, growth : (3,) float64
        The spacing at ``t`` is ``norm(offset + t * growth)``.
    """
    o0, d0 = mouse_ray(renderer, x, y)
    o1, d1 = mouse_ray(renderer, x + 1.0, y)
    return o1 - o0, d1 - d0


def sphere_entries(origin, direction, centers, radius):
    """Where the ray ``origin + t * direction`` enters each sphere.

    Parameters
    ----------
    origin, direction : (3,) float
        ``direction`` of unit length.
    centers : (N, 3) float
    radius : float or (N,) float

    Returns
    -------
    t : (N,) float64
        The ray parameter of the entry point; ``inf`` for a sphere the ray misses or one
        wholly behind the origin.
    """
    rel = np.asarray(centers, dtype=float).reshape(-1, 3) - np.asarray(origin, dtype=float)
    along = rel @ np.asarray(direction, dtype=float)
    miss2 = np.einsum("ij,ij->i", rel, rel) - along * along
    r2 = np.broadcast_to(np.asarray(radius, dtype=float) ** 2, along.shape)
    hit = (miss2 <= r2) & (along + np.sqrt(r2) > 0.0)
    t = np.full(along.shape, np.inf)
    t[hit] = along[hit] - np.sqrt(r2[hit] - miss2[hit])
    return t


def pick_sphere(origin, direction, centers, radius):
    """The sphere the ray meets first, or None.

    Overlapping or occluding spheres resolve to the one whose surface the ray enters first
    (the nearest to the viewer along the ray).

    Parameters
    ----------
    origin, direction : (3,) float
    centers : (N, 3) float
    radius : float or (N,) float

    Returns
    -------
    index : int or None
    t : float
        The entry's ray parameter (``inf`` when nothing is hit).
    """
    t = sphere_entries(origin, direction, centers, radius)
    if not len(t):
        return None, np.inf
    k = int(np.argmin(t))
    return (k, float(t[k])) if np.isfinite(t[k]) else (None, np.inf)


def closest_on_line(point, direction, origin, ray):
    """Parameter ``s`` of the point ``point + s * direction`` closest to the line
    ``origin + t * ray`` (both directions unit), or None when they are parallel."""
    w = point - origin
    b = float(direction @ ray)
    denom = 1.0 - b * b
    if denom < 1e-6:  # looking along the axis: the closest point is undefined
        return None
    return (b * float(ray @ w) - float(direction @ w)) / denom
