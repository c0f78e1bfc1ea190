"""The graph on sphere centres: edges whose segment stays inside the mesh, with shortest paths.

Two centres are joined when their spheres overlap or nearly touch (within
``REACH`` times the sum of their radii) and the straight segment between them stays inside
the mesh. Bones of the reduced skeleton map to shortest paths in this graph (Pinocchio
section 4), so a path's length measures a limb along its bends and a path can never leave
the body through a gap (between the legs, between an arm and the chest).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, dijkstra
from scipy.spatial import cKDTree

__all__ = ["MedialGraph", "medial_graph"]

#: How far apart (in sums of radii) two centres may be and still be joined: beyond touching
#: spheres, so that a string of small spheres in a tapering limb stays connected.
REACH = 2.0


@dataclass
class MedialGraph:
    """Sphere centres joined through the inside of the mesh.

    Attributes
    ----------
    points : (N, 3) float64
    radii : (N,) float64
    edges : (E, 2) int64
    dist : (N, N) float64
        Shortest path lengths (``inf`` between components).
    pred : (N, N) int32
        Predecessor matrix of the shortest paths (scipy's convention, -9999: none).
    """

    points: np.ndarray
    radii: np.ndarray
    edges: np.ndarray
    dist: np.ndarray
    pred: np.ndarray

    def path(self, a, b):
        """Vertex indices of the shortest path from ``a`` to ``b`` (both included)."""
        if a == b:
            return [int(a)]
        if not np.isfinite(self.dist[a, b]):
            return []
        out = [int(b)]
        while out[-1] != a:
            out.append(int(self.pred[a, out[-1]]))
        return out[::-1]


def medial_graph(field, centres, radii):
    """Join sphere centres whose segment stays inside ``field``; keep the largest component.

    Parameters
    ----------
    field : DistanceField
    centres : (N, 3) float64
    radii : (N,) float64

    Returns
    -------
    MedialGraph
    """
    n = len(centres)
    if n == 0:
        empty = np.zeros((0, 0))
        return MedialGraph(centres, radii, np.zeros((0, 2), np.int64), empty,
                           empty.astype(np.int32))
    tree = cKDTree(centres)
    pairs = tree.query_pairs(REACH * 2.0 * float(radii.max()), output_type="ndarray")
    if len(pairs):
        gap = np.linalg.norm(centres[pairs[:, 0]] - centres[pairs[:, 1]], axis=1)
        pairs = pairs[gap < REACH * (radii[pairs[:, 0]] + radii[pairs[:, 1]])]
    if len(pairs):
        pairs = pairs[field.segments_inside(centres[pairs[:, 0]], centres[pairs[:, 1]])]
    lengths = np.linalg.norm(centres[pairs[:, 0]] - centres[pairs[:, 1]], axis=1) if len(
        pairs) else np.zeros(0)
    adj = coo_matrix((lengths, (pairs[:, 0], pairs[:, 1])), shape=(n, n)).tocsr() if len(
        pairs) else coo_matrix((n, n)).tocsr()
    _, label = connected_components(adj, directed=False)
    # Stray spheres (in a separate accessory, an eye) would only distract the search.
    size = np.bincount(label, weights=radii ** 3)
    keep = np.flatnonzero(label == np.argmax(size))
    remap = np.full(n, -1)
    remap[keep] = np.arange(len(keep))
    if len(pairs):
        both = (remap[pairs[:, 0]] >= 0) & (remap[pairs[:, 1]] >= 0)
        pairs, lengths = remap[pairs[both]], lengths[both]
    m = len(keep)
    adj = coo_matrix((lengths, (pairs[:, 0], pairs[:, 1])), shape=(m, m)).tocsr()
    dist, pred = dijkstra(adj, directed=False, return_predecessors=True)
    return MedialGraph(centres[keep], radii[keep], np.asarray(pairs, np.int64), dist, pred)
