"""Which bones a vertex sees: the nearest visible joint(s) of every vertex (:mod:`.heat`).

A bone is visible from a vertex when the segment from the vertex to its nearest point on the
bone crosses no triangle (:mod:`.visibility`) and that point lies behind the vertex's surface.
Joints are tried nearest first, at most :data:`MAX_ROUNDS` of them; bones within
:data:`TIE` of the nearest visible one share the vertex.
"""
from __future__ import annotations

import numpy as np

from .heat_bones import nearest_on_segment

__all__ = ["visible_nearest", "visible", "normal_biased", "TIE", "MAX_ROUNDS", "RING_BEHIND"]

TIE = 1e-4              # bones within this relative distance of the nearest share the vertex
MAX_ROUNDS = 8          # how many nearest bones to try before a vertex sees none
RING_BEHIND = 0.75      # see visible


def visible_nearest(wv, rank, dist, seg, starts, ends, report, test):
    """Nearest visible joint(s) of every vertex, tried in order of ``rank``.

    Returns
    -------
    pairs_v, pairs_j : (P,) int
        Vertex and joint column of each (vertex, visible nearest joint) pair; ties give a
        vertex several pairs.
    best : (W,) float64
        Distance to the nearest visible joint, ``inf`` where none was found.
    """
    n, nj = rank.shape
    rounds = min(nj, MAX_ROUNDS)
    best_rank = np.full(n, np.inf)
    best = np.full(n, np.inf)
    pv, pj = [], []
    rows = np.arange(n)
    # Round 0 on every vertex, straight from ``rank`` (no copy of the (W, J) matrix).
    cand = rank.argmin(axis=1)
    rr = rank[rows, cand]
    ok = test(rows, cand)
    best_rank[ok], best[ok] = rr[ok], dist[ok, cand[ok]]
    pv.append(rows[ok])
    pj.append(cand[ok])
    # Which vertices need a second round: those that saw nothing, and those whose second
    # nearest joint ties with the first (found by masking the first in place, then undoing).
    rank[rows, cand] = np.inf
    second = rank.min(axis=1)
    more = np.flatnonzero(~ok | (second <= rr * (1 + TIE)))
    left = rank[more]
    rank[rows, cand] = rr
    active = more
    report(0.2 + 0.25 / rounds)
    for r in range(1, rounds):
        cand = left.argmin(axis=1)
        rr = left[np.arange(len(active)), cand]
        go = (np.isinf(best_rank[active]) | (rr <= best_rank[active] * (1 + TIE))) & \
            np.isfinite(rr)
        active, cand, rr, left = active[go], cand[go], rr[go], left[go]
        if len(active) == 0:
            break
        ok = test(active, cand)
        first = ok & np.isinf(best_rank[active])
        best_rank[active[first]] = rr[first]
        best[active[first]] = dist[active[first], cand[first]]
        pv.append(active[ok])
        pj.append(cand[ok])
        left[np.arange(len(active)), cand] = np.inf
        report(0.2 + 0.25 * (r + 1) / rounds)
    return np.concatenate(pv), np.concatenate(pj), best


def visible(wv, normals, ring, verts, joints, seg, starts, ends, rays, front_only, behind,
            offset, label=None):
    """(N,) bool: joint ``joints[n]`` is visible from vertex ``verts[n]``: the segment to
    its nearest point crosses no triangle, and that point lies behind the vertex's surface:
    ``cos(normal, to bone) < behind``, and behind (or in) the planes of the vertex's own
    triangles that hold ``RING_BEHIND`` of their area (a bone in front of the skin is
    outside the body; at a sharp rim the averaged normal alone cannot tell)."""
    s = seg[verts, joints]
    target = nearest_on_segment(wv[verts], starts[s], ends[s])
    to_bone = target - wv[verts]
    cos = np.einsum("ij,ij->i", to_bone, normals[verts]) / np.maximum(
        np.linalg.norm(to_bone, axis=1), 1e-300)
    ok = cos < behind
    if behind < 1.0:  # behind >= 1 turns the side tests off
        ok[ok] = ring.behind_share(verts[ok], to_bone[ok]) >= RING_BEHIND
    # A vertex on the bone (a cap's centre on a root) has no direction to it: it sees it.
    on = np.einsum("ij,ij->i", to_bone, to_bone) <= offset * offset
    ok[on] = True
    # Start a hair inside, between the way to the bone and against the normal, and test
    # the vertex's own triangles too. Against the normal alone, a start at a sharp rim
    # can fall outside the rim's other face when the averaged normal is far from that
    # face's (a cylinder's end ring, mostly side faces: every segment to the bone then
    # crossed the end cap); along the segment alone, a segment leaving tangentially along
    # a wall starts outside and is never blocked. The last bit of the segment stays free:
    # a bone lying on the skin is still seen.
    unit = to_bone[ok] / np.maximum(np.linalg.norm(to_bone[ok], axis=1), 1e-300)[:, None]
    step = unit - normals[verts[ok]]
    step /= np.maximum(np.linalg.norm(step, axis=1), 1e-300)[:, None]
    start = wv[verts[ok]] + offset * step
    test = ok & ~on
    ok[test] = ~rays.blocked(start[~on[ok]], target[test], t_lo=0.0, t_hi=1.0 - 1e-4,
                             front_only=front_only,
                             part=None if label is None else label[verts[test]])
    return ok


def normal_biased(wv, normals, starts, ends, seg, dist):
    """Blender's ranking distance ``d / (0.5 (cos + 1.001))``, cos between the vertex
    normal and the direction from the bone to the vertex."""
    out = np.empty_like(dist)
    for j in range(dist.shape[1]):  # per joint column (tens)
        s = seg[:, j]
        d = wv - nearest_on_segment(wv, starts[s], ends[s])
        cos = np.einsum("ij,ij->i", d, normals) / np.maximum(np.linalg.norm(d, axis=1), 1e-300)
        out[:, j] = dist[:, j] / (0.5 * (cos + 1.001))
    return out
