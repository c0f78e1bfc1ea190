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
#: Every centre is also offered to its nearest few (then kept if the segment is inside).
NEAREST = 6


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
    # and each centre to its nearest few whatever their radii: where the medial cells thin
    # out (a tapering leg) the spheres along it may sit further apart than they are wide
    k = min(NEAREST + 1, n)
    if k > 1:
        _, near = tree.query(centres, k=k)
        extra = np.stack([np.repeat(np.arange(n), k - 1), near[:, 1:].ravel()], axis=1)
        extra = np.sort(extra, axis=1)
        pairs = np.unique(np.concatenate([pairs.reshape(-1, 2), extra]), axis=0)
    pairs = pairs.reshape(-1, 2)
    if len(pairs):
        pairs = pairs[field.segments_inside(centres[pairs[:, 0]], centres[pairs[:, 1]])]
    pairs = _bridge(field, centres, pairs)
    lengths = np.linalg.norm(centres[pairs[:, 0]] - centres[pairs[:, 1]], axis=1)
    adj = coo_matrix((lengths, (pairs[:, 0], pairs[:, 1])), shape=(n, n)).tocsr()
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


def _bridge(field, centres, pairs, tries=8):
    """Join separate components through the inside where a straight segment allows.

    Where a part is thinner than the grid resolves (a cow's hock at a cell across), the
    medial cells stop and the spheres on either side are further apart than any sphere's
    reach; the straight segment between the nearest spheres of the two pieces still runs
    inside, so it is added. Joins components to the largest one, nearest pairs first.
    """
    n = len(centres)
    added = True
    while added:
        added = False
        adj = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        count, label = connected_components(adj, directed=False)
        if count == 1:
            break
        sizes = np.bincount(label)
        main = np.argmax(sizes)
        in_main = np.flatnonzero(label == main)
        tree = cKDTree(centres[in_main])
        k = min(tries, len(in_main))
        new = []
        for c in np.argsort(-sizes):
            if c == main:
                continue
            part = np.flatnonzero(label == c)
            dist, near = tree.query(centres[part], k=k)
            dist, near = dist.reshape(len(part), k), near.reshape(len(part), k)
            order = np.argsort(dist, axis=None)[:tries]
            i, j = np.unravel_index(order, dist.shape)
            a, b = part[i], in_main[near[i, j]]
            ok = np.flatnonzero(field.segments_inside(centres[a], centres[b]))
            if len(ok):
                new.append(sorted((a[ok[0]], b[ok[0]])))
        if new:
            pairs = np.concatenate([pairs, np.asarray(new, dtype=pairs.dtype)])
            added = True
    return pairs
