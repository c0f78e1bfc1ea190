"""The mirror plane of a character's surface (its left-right axis), and surface samples.

Used by :mod:`.orient`.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import minimize
from scipy.spatial import cKDTree

from ...binding.laplacian import face_areas
from ...model.transforms import tangents
from ...model.transforms import unit

__all__ = ["symmetry_plane", "surface_samples", "volume_centroid", "SAMPLES"]

SAMPLES = 4000


def surface_samples(vertices, faces, n=SAMPLES, seed=0):
    """(n, 3) points spread uniformly over the surface (area-weighted, deterministic)."""
    tri = vertices[faces]
    area = face_areas(vertices, faces)
    rng = np.random.default_rng(seed)
    pick = rng.choice(len(faces), size=n, p=area / area.sum())
    r1, r2 = rng.random(n), rng.random(n)
    s = np.sqrt(r1)
    a, b, c = 1 - s, s * (1 - r2), s * r2
    t = tri[pick]
    return a[:, None] * t[:, 0] + b[:, None] * t[:, 1] + c[:, None] * t[:, 2]


def volume_centroid(vertices, faces):
    """Centre of the enclosed volume (signed tetrahedra from the origin); the mean vertex
    when the mesh encloses next to nothing (open or inconsistently oriented)."""
    tri = vertices[faces] - vertices.mean(axis=0)
    vol = np.einsum("fi,fi->f", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])) / 6.0
    total = vol.sum()
    extent = np.ptp(vertices, axis=0)
    if abs(total) < 1e-3 * np.prod(np.maximum(extent, 1e-12)):
        return vertices.mean(axis=0)
    return vertices.mean(axis=0) + (vol[:, None] * tri.sum(axis=1) / 4.0).sum(axis=0) / total


def _fibonacci(n):
    """(n, 3) directions spread over the upper half sphere (a direction and its negative are
    the same mirror)."""
    i = np.arange(n) + 0.5
    z = i / n
    phi = np.pi * (1 + 5 ** 0.5) * i
    r = np.sqrt(1 - z * z)
    return np.c_[r * np.cos(phi), r * np.sin(phi), z]


def _mirror_cost(points, tree, normal, offset, centre):
    n = unit(normal)
    d = (points - centre) @ n - offset
    dist, _ = tree.query(points - 2 * d[:, None] * n, k=1)
    return float(dist.mean())


def symmetry_plane(points, size, fixed=None):
    """The best mirror plane of ``points`` (see the module notes).

    Parameters
    ----------
    points : (N, 3) float64
    size : float
    fixed : (3,) float64, optional
        A direction given by the user, which lies in the plane.

    Returns
    -------
    normal : (3,) float64
    mismatch : float
        Mean distance of a reflected point to the nearest point, as a fraction of ``size``.
    """
    centre = points.mean(axis=0)
    tree = cKDTree(points)
    sub = points[:: max(1, len(points) // 1000)]
    if fixed is None:
        _, _, vt = np.linalg.svd(points - centre, full_matrices=False)
        cands = np.vstack([_fibonacci(240), vt])
    else:
        e1, e2 = tangents(fixed)
        th = np.linspace(0, np.pi, 90, endpoint=False)
        cands = np.outer(np.cos(th), e1) + np.outer(np.sin(th), e2)
    coarse = points[:: max(1, len(points) // 300)]   # screening: 300 points tell planes apart
    scores = [_mirror_cost(coarse, tree, c, 0.0, centre) for c in cands]
    best = None
    for c in cands[np.argsort(scores)[:2]]:
        e1, e2 = tangents(c) if fixed is None else (unit(np.cross(fixed, c)), np.zeros(3))

        def f(x, c=c, e1=e1, e2=e2):
            return _mirror_cost(sub, tree, c + x[0] * e1 + x[1] * e2, x[2] * size, centre)
        r = minimize(f, np.zeros(3), method="Nelder-Mead",
                     options={"xatol": 1e-4, "fatol": 1e-7 * size, "maxiter": 300,
                              "initial_simplex": np.vstack([np.zeros(3),
                                                            np.diag([0.05, 0.05, 0.01])])})
        if best is None or r.fun < best[0]:
            best = (r.fun, unit(c + r.x[0] * e1 + r.x[1] * e2), r.x[2] * size)
    _, normal, offset = best
    return normal, _mirror_cost(points, tree, normal, offset, centre) / size


