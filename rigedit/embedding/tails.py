"""Tails to the end of their branch.

The search holds a tail's length only weakly (``penalties.W_LENGTH_TAIL``), but a length
prior, however weak, still prefers the template's length: on a mesh whose tail is twice the
template's it stops half-way. What the mesh does say is where its branch ends, so the tail's
end joint moves on from its vertex to the furthest graph vertex whose shortest path from the
tail's base runs through it (within ``SLACK``) and that lies beyond it (away from the base).
A stub ends where it is.
"""
from __future__ import annotations

import numpy as np

__all__ = ["extend_tails", "SLACK"]

#: A vertex u is "through" the tail end v when the way base -> v -> u is at most this much
#: longer than the shortest way base -> u (the graph's paths zigzag between sphere centres).
SLACK = 0.05


def extend_tails(graph, template, vertex):
    """Move each embedded tail's end vertex to the end of its branch.

    Parameters
    ----------
    graph : MedialGraph
    template : ReducedTemplate
        ``tail`` marks the reduced joints that end a tail.
    vertex : (R,) int
        Graph vertex of each reduced joint (-1 where carried).

    Returns
    -------
    (R,) int
        A copy, the tails' ends moved.
    """
    out = np.array(vertex)
    if template.tail is None:
        return out
    pts, dist = graph.points, graph.dist
    for r in np.flatnonzero(template.tail):
        a, v = out[template.parent[r]], out[r]
        if a < 0 or v < 0:
            continue
        via = dist[a, v] + dist[v]
        beyond = (pts - pts[v]) @ (pts[v] - pts[a]) > 0
        ok = np.isfinite(via) & (via <= (1.0 + SLACK) * dist[a]) & beyond
        ok[[x for x in out if x >= 0]] = False
        if ok.any():
            cand = np.flatnonzero(ok)
            out[r] = int(cand[np.argmax(dist[a, cand])])
    return out
