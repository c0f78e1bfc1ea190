"""Surface operators for heat weights: welding, a clamped cotangent Laplacian, lumped mass.

The operator must stay well-posed on whatever mesh a user brings: split vertices (glTF splits
at UV seams), non-manifold edges, slivers, isolated vertices. Cotangent weights are computed
per triangle, clamped to ``[0, COT_MAX]`` (a negative weight breaks the maximum principle, so
a weight could leave [0, 1]; an unbounded one makes a sliver dominate), and summed over every
triangle that shares an edge, so a non-manifold edge is simply the sum of its triangles.
Each triangle's clamped matrix is a graph Laplacian with non-negative weights, so the sum is
symmetric positive semi-definite with the constants on each connected part as its kernel.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

__all__ = ["weld", "clean_faces", "cotangent_laplacian", "components", "vertex_normals",
           "oriented_face_normals", "OneRing", "face_areas", "COT_MAX"]

# cot(1 degree) ~ 57: angles below one degree are treated as one degree.
COT_MAX = 1.0 / np.tan(np.radians(1.0))


def weld(vertices, tol):
    """Merge vertices closer than ``tol`` (split seams, duplicates).

    Parameters
    ----------
    vertices : (V, 3) float64
    tol : float
        Distance below which two vertices are the same point.

    Returns
    -------
    rep : (V,) int64
        The welded index of each input vertex, in ``[0, W)``.
    welded : (W, 3) float64
        One position per welded vertex (the first member's).
    """
    n = len(vertices)
    pairs = cKDTree(vertices).query_pairs(tol, output_type="ndarray") if n > 1 else \
        np.empty((0, 2), dtype=np.int64)
    if len(pairs) == 0:
        return np.arange(n), vertices
    g = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, labels = connected_components(g, directed=False)
    # Number groups in order of their first member so the map is stable.
    first = np.full(labels.max() + 1, n, dtype=np.int64)
    np.minimum.at(first, labels, np.arange(n))
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    rep = rank[labels]
    return rep, vertices[first[order]]


def clean_faces(faces):
    """Drop faces that repeat a vertex (degenerate after welding) and repeated faces.

    Parameters
    ----------
    faces : (F, 3) int64

    Returns
    -------
    faces : (F', 3) int64
    """
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    ok = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
    f = f[ok]
    if len(f):
        _, keep = np.unique(np.sort(f, axis=1), axis=0, return_index=True)
        f = f[np.sort(keep)]
    return f


def face_areas(vertices, faces):
    """(F,) float64 areas of the triangles ``faces`` (F, 3) of ``vertices`` (V, 3)."""
    tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces, dtype=np.int64)]
    return 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)


def cotangent_laplacian(vertices, faces):
    """Clamped cotangent stiffness matrix and lumped (barycentric) mass.

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int64
        No repeated vertex within a face (see :func:`clean_faces`).

    Returns
    -------
    L : (V, V) scipy.sparse.csc_matrix
        Positive semi-definite: ``x @ L @ x`` is the Dirichlet energy of ``x``.
    mass : (V,) float64
        A third of the area of the triangles around each vertex (0 for a vertex in none).
    """
    n = len(vertices)
    v = [vertices[faces[:, k]] for k in range(3)]
    # Angle at corner k is between the two edges leaving it; its cotangent weights the
    # opposite edge (k+1, k+2).
    rows, cols, vals = [], [], []
    area2 = np.linalg.norm(np.cross(v[1] - v[0], v[2] - v[0]), axis=1)
    safe = np.maximum(area2, 1e-300)
    for k in range(3):
        a, b, c = v[k], v[(k + 1) % 3], v[(k + 2) % 3]
        e1, e2 = b - a, c - a
        cot = np.einsum("ij,ij->i", e1, e2) / safe
        # A zero-area triangle has no defined angles: it carries no stiffness.
        cot = np.where(area2 > 0, np.clip(cot, 0.0, COT_MAX), 0.0) * 0.5
        rows.append(faces[:, (k + 1) % 3])
        cols.append(faces[:, (k + 2) % 3])
        vals.append(cot)
    i = np.concatenate(rows)
    j = np.concatenate(cols)
    w = np.concatenate(vals)
    off = sp.coo_matrix((-w, (i, j)), shape=(n, n))
    off = (off + off.T).tocsc()
    diag = -np.asarray(off.sum(axis=1)).ravel()
    L = (off + sp.diags(diag)).tocsc()
    mass = np.bincount(faces.ravel(), weights=np.repeat(area2 / 6.0, 3), minlength=n)
    return L, mass


def components(n, faces):
    """Connected parts of the mesh graph.

    Parameters
    ----------
    n : int
        Number of vertices.
    faces : (F, 3) int64

    Returns
    -------
    count : int
    labels : (V,) int
        Part of each vertex; a vertex in no face is a part of its own.
    """
    if len(faces) == 0:
        return n, np.arange(n)
    i = faces[:, [0, 1, 2]].ravel()
    j = faces[:, [1, 2, 0]].ravel()
    g = sp.coo_matrix((np.ones(len(i), dtype=np.int8), (i, j)), shape=(n, n))
    return connected_components(g, directed=False)


def oriented_face_normals(vertices, faces, labels=None):
    """(F, 3) face normals of length twice the face's area, turned outward part by part.

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int64
    labels : (V,) int, optional
        Connected part of each vertex (:func:`components`); computed when omitted. A part
        whose signed volume is negative (faces wound inward) has its normals flipped.
    """
    if labels is None:
        labels = components(len(vertices), faces)[1]
    tri = vertices[faces]
    fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    part = labels[faces[:, 0]]
    parts = labels.max() + 1 if len(labels) else 0
    # Signed volume about each part's own centre: for a closed part the centre does not
    # matter, for an open one (a sleeve, a skirt) it keeps the sign from depending on where
    # the part sits relative to the origin.
    count = np.maximum(np.bincount(labels, minlength=parts), 1)
    centre = np.stack([np.bincount(labels, vertices[:, k], parts) for k in range(3)], 1)
    centre /= count[:, None]
    volume = np.bincount(part, weights=np.einsum("ij,ij->i", fn, tri[:, 0] - centre[part]),
                         minlength=parts)
    fn *= np.where(volume[part] < 0, -1.0, 1.0)[:, None]
    return fn


class OneRing:
    """Each vertex's triangles, to ask which way is into the body at a vertex.

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int64
    labels : (V,) int, optional
        As for :func:`oriented_face_normals`.
    """

    def __init__(self, vertices, faces, labels=None):
        fn = oriented_face_normals(vertices, faces, labels)
        area = np.linalg.norm(fn, axis=1)
        self.unit = fn / np.maximum(area, 1e-300)[:, None]
        n, f = len(vertices), len(faces)
        self.inc = sp.csr_matrix((np.repeat(area, 3), (faces.ravel(),
                                                        np.repeat(np.arange(f), 3))),
                                 shape=(n, f))
        self.total = np.maximum(np.asarray(self.inc.sum(axis=1)).ravel(), 1e-300)

    def behind_share(self, verts, dirs, grazing=0.02):
        """(N,) float: the share of the one-ring area of ``verts[n]`` whose face plane has
        ``dirs[n]`` (N, 3) behind it (pointing into the body) or in it (cosine with the
        face normal below ``grazing``: from a rim, a bone at a cap's centre lies in the
        cap's plane)."""
        rows = self.inc[verts]
        r = np.repeat(np.arange(len(verts)), np.diff(rows.indptr))
        unit = dirs / np.maximum(np.linalg.norm(dirs, axis=1), 1e-300)[:, None]
        behind = np.einsum("ij,ij->i", self.unit[rows.indices], unit[r]) < grazing
        return np.bincount(r, weights=rows.data * behind, minlength=len(verts)) \
            / self.total[verts]


def vertex_normals(vertices, faces, labels=None):
    """Unit area-weighted vertex normals, turned outward part by part
    (:func:`oriented_face_normals`, whose parameters these are).

    Returns
    -------
    normals : (V, 3) float64
        Zero for a vertex in no triangle.
    """
    fn = oriented_face_normals(vertices, faces, labels)
    normals = np.zeros_like(vertices)
    for k in range(3):
        np.add.at(normals, faces[:, k], fn)
    return normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
