"""Weight painting maths: one brush dab on the skin weights (pure numpy/scipy).

A dab changes the weight of one joint (the painted joint) at the vertices under the brush,
each by ``strength`` times its falloff factor, then renormalises every touched row:

- the weights of *locked* joints never change;
- the other unlocked joints take what the painted joint gave or took, in proportion to their
  current weights; when there is none (a vertex held by the painted joint alone) the weight
  taken away goes to a ``fallback`` joint (the editor passes the painted joint's parent),
  and when there is no fallback either the painted joint keeps it (rows must sum to 1);
- at most K influences are kept per vertex (K: the binding's width); locked joints come
  first, then the largest; weights below ``min_weight`` are dropped; what was dropped is
  shared among the kept unlocked joints in proportion, so rows still sum to 1.

Modes: ``add`` (w + a), ``subtract`` (w - a), ``set`` (w moved towards ``value`` by a fraction
a) and ``smooth`` (w moved towards the mean of its neighbours' weights by a fraction a), with
``a = strength * falloff``.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

__all__ = ["MODES", "falloff", "brush_vertices", "joint_column", "vertex_adjacency",
           "mirror_vertices", "paint", "paint_mirrored"]

MODES = ("add", "subtract", "set", "smooth")


def falloff(distance, radius):
    """Smooth brush falloff ``(1 - (d / r)^2)^2``: 1 at the centre, 0 at and beyond the
    radius, with a zero slope at both ends (no visible rim where the brush stops).

    Parameters
    ----------
    distance : (N,) float
    radius : float

    Returns
    -------
    (N,) float64 in [0, 1]
    """
    t = np.clip(np.asarray(distance, dtype=np.float64) / float(radius), 0.0, 1.0)
    return (1.0 - t * t) ** 2


def brush_vertices(points, center, radius):
    """Vertices strictly inside the brush sphere and their falloff factors.

    Parameters
    ----------
    points : (V, 3) float
        Vertex positions as shown (the skinned mesh).
    center : (3,) float
        The surface point under the mouse.
    radius : float
        Brush radius in scene units.

    Returns
    -------
    verts : (N,) int64
    factors : (N,) float64 in (0, 1]
    """
    if not radius > 0:
        raise ValueError(f"expected a positive brush radius, got {radius}")
    d = np.linalg.norm(np.asarray(points, dtype=np.float64) - np.asarray(center, float), axis=1)
    verts = np.flatnonzero(d < radius)
    f = falloff(d[verts], radius)
    keep = f > 0
    return verts[keep], f[keep]


def joint_column(indices, weights, joint):
    """(V,) float64: every vertex's weight of ``joint`` from (V, K) influences."""
    return np.where(np.asarray(indices) == joint, weights, 0.0).sum(axis=1)


def vertex_adjacency(faces, num_vertices):
    """(V, V) CSR matrix with 1 where two vertices share a triangle edge (no diagonal)."""
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    a = np.concatenate([f[:, 0], f[:, 1], f[:, 2]])
    b = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
    m = sp.coo_matrix((np.ones(2 * len(a)), (np.concatenate([a, b]), np.concatenate([b, a]))),
                      shape=(num_vertices, num_vertices)).tocsr()
    m.setdiag(0)
    m.eliminate_zeros()
    m.data[:] = 1.0
    return m


def mirror_vertices(vertices, axis=0, tolerance=0.01):
    """For each vertex its mirror image across the plane normal to ``axis`` through the
    middle of the mesh's extent along it.

    Parameters
    ----------
    vertices : (V, 3) float
        Rest (bind) positions.
    axis : int
        The left-right axis.
    tolerance : float
        Largest distance between a reflected vertex and its nearest vertex, as a fraction of
        the bounding-box diagonal, for the two to count as mirrors.

    Returns
    -------
    (V,) int64: the mirror vertex, or -1 where none is within the tolerance.
    """
    v = np.asarray(vertices, dtype=np.float64)
    if len(v) == 0:
        return np.zeros(0, dtype=np.int64)
    lo, hi = v.min(axis=0), v.max(axis=0)
    reflected = v.copy()
    reflected[:, axis] = (lo[axis] + hi[axis]) - v[:, axis]
    dist, nearest = cKDTree(v).query(reflected)
    limit = tolerance * float(np.linalg.norm(hi - lo))
    return np.where(dist <= limit, nearest, -1).astype(np.int64)


def paint(indices, weights, num_joints, joint, verts, factors, mode="add", strength=0.5, *,
          value=1.0, locked=(), adjacency=None, fallback=None, min_weight=1e-3):
    """One brush dab on ``joint`` (see the module notes).

    Parameters
    ----------
    indices : (V, K) int
    weights : (V, K) float, rows sum to 1
    num_joints : int
    joint : int
        The painted joint; it must not be locked.
    verts : (N,) int
        Vertices under the brush (no repeats).
    factors : (N,) float in [0, 1]
        Their falloff.
    mode : {"add", "subtract", "set", "smooth"}
    strength : float in [0, 1]
    value : float in [0, 1]
        The target weight of ``set``.
    locked : iterable of int
        Joints whose weights must not change.
    adjacency : (V, V) sparse, optional
        Vertex neighbours (:func:`vertex_adjacency`); needed by ``smooth``.
    fallback : int, optional
        Joint that receives what ``joint`` loses at vertices with no other unlocked influence.
    min_weight : float
        Influences below this are dropped.

    Returns
    -------
    indices : (V, K) int32
    weights : (V, K) float64
        New arrays; rows outside ``verts`` are unchanged.
    """
    if mode not in MODES:
        raise ValueError(f"expected a brush mode in {MODES}, got {mode!r}")
    lock = np.zeros(num_joints, dtype=bool)
    lock[list(locked)] = True
    if not 0 <= joint < num_joints:
        raise ValueError(f"expected a joint in [0, {num_joints - 1}], got {joint}")
    if lock[joint]:
        raise ValueError("the painted joint is locked")
    indices = np.asarray(indices)
    out_idx = indices.astype(np.int32, copy=True)
    out_w = np.array(weights, dtype=np.float64, copy=True)
    verts = np.asarray(verts, dtype=np.int64)
    if len(verts) == 0:
        return out_idx, out_w
    k = indices.shape[1]
    a = np.clip(np.asarray(factors, dtype=np.float64), 0.0, 1.0) * float(np.clip(strength, 0, 1))
    n = len(verts)
    rows = np.zeros((n, num_joints))
    np.add.at(rows, (np.repeat(np.arange(n), k), indices[verts].ravel()),
              out_w[verts].ravel())
    cur = rows[:, joint]
    room = np.clip(1.0 - rows[:, lock].sum(axis=1), 0.0, 1.0)
    if mode == "smooth":
        if adjacency is None:
            raise ValueError("smooth needs the vertex adjacency")
        goal = _neighbour_mean(indices, weights, joint, verts, adjacency, cur)
    else:
        goal = value
    target = np.clip(_moved(mode, cur, a, goal), 0.0, room)
    _share_the_rest(rows, joint, target, room, lock, fallback)
    idx, vals = _top_k(rows, k, lock, min_weight)
    out_idx[verts] = idx
    out_w[verts] = vals
    return out_idx, out_w


def _moved(mode, cur, a, goal):
    """(N,) the painted joint's weights ``cur`` after a dab of amounts ``a`` (N,): added,
    subtracted, or moved towards ``goal`` (the set value, or the neighbours' mean)."""
    if mode == "add":
        return cur + a
    if mode == "subtract":
        return cur - a
    if mode == "set":
        return cur + a * (float(goal) - cur)
    return cur + a * (goal - cur)


def _neighbour_mean(indices, weights, joint, verts, adjacency, cur):
    """(N,) the mean weight of ``joint`` over each of ``verts``' neighbours (``cur``, its
    own, where it has none)."""
    col = joint_column(indices, weights, joint)
    adj = adjacency[verts]
    deg = np.asarray(adj.sum(axis=1)).ravel()
    return np.divide(adj @ col, deg, out=cur.copy(), where=deg > 0)


def _share_the_rest(rows, joint, target, room, lock, fallback):
    """Put ``target`` (N,) as the painted joint's weight in ``rows`` (N, J), in place, and
    give what is left of ``room`` (what the locked joints leave) to the other unlocked
    joints in proportion to their weights; where there are none, to the ``fallback``
    joint, else the painted joint keeps it (``target`` is changed there too)."""
    n = len(rows)
    others = ~lock
    others[joint] = False
    other_sum = rows[:, others].sum(axis=1)
    rest = room - target
    has_others = other_sum > 1e-12
    scale = np.divide(rest, other_sum, out=np.zeros(n), where=has_others)
    rows[:, others] *= scale[:, None]
    lonely = ~has_others & (rest > 0)
    if fallback is not None and 0 <= fallback < len(lock) and not lock[fallback] \
            and fallback != joint:
        rows[lonely, fallback] = rest[lonely]
    else:
        target[lonely] = room[lonely]  # nobody to give it to: the joint keeps it
    rows[:, joint] = target


def _top_k(rows, k, lock, min_weight):
    """Keep at most ``k`` influences per row (locked ones first, then the largest), drop
    unlocked ones below ``min_weight``, and give the dropped weight to the kept unlocked
    ones in proportion. Returns (N, k) int32 indices and float64 weights, largest first."""
    n, j = rows.shape
    locked_here = lock[None, :] & (rows > 0)
    priority = rows + 2.0 * locked_here  # locked influences always survive
    order = np.argsort(-priority, axis=1, kind="stable")[:, :k]
    vals = np.take_along_axis(rows, order, axis=1)
    is_locked = lock[order]
    vals[(vals < min_weight) & ~is_locked] = 0.0
    if order.shape[1] < k:  # fewer joints than influences: pad with zero weights
        pad = k - order.shape[1]
        order = np.hstack([order, np.repeat(order[:, :1], pad, axis=1)])
        vals = np.hstack([vals, np.zeros((n, pad))])
        is_locked = np.hstack([is_locked, np.zeros((n, pad), dtype=bool)])
    free = np.where(is_locked, 0.0, vals)
    free_sum = free.sum(axis=1)
    want = 1.0 - np.where(is_locked, vals, 0.0).sum(axis=1)
    ok = free_sum > 0
    vals = np.where(is_locked | ~ok[:, None], vals,
                    free * np.divide(want, free_sum, out=np.ones(n), where=ok)[:, None])
    total = vals.sum(axis=1)
    bad = total <= 0
    if bad.any():  # cannot happen with valid input rows; never leave a vertex unweighted
        vals[bad, 0] = 1.0
    resort = np.argsort(-vals, axis=1, kind="stable")
    return (np.take_along_axis(order, resort, axis=1).astype(np.int32),
            np.take_along_axis(vals, resort, axis=1))


def paint_mirrored(indices, weights, num_joints, joint, verts, factors, mirror_verts,
                   mirror_joints, **options):
    """A dab and its mirror image: the same change on ``mirror_joints[joint]`` at the mirror
    vertices of ``verts`` (those that have one). Where both land on the same vertex with the
    same joint (the middle of a central bone) the dab is applied once, with the larger
    factor. Parameters as :func:`paint`, plus ``mirror_verts`` (V,) (-1: none) and
    ``mirror_joints`` (J,)."""
    other = int(mirror_joints[joint])
    mv = np.asarray(mirror_verts)[np.asarray(verts, dtype=np.int64)]
    has = mv >= 0
    mv, mf = mv[has], np.asarray(factors, dtype=np.float64)[has]
    if other == joint:
        allv = np.concatenate([np.asarray(verts, dtype=np.int64), mv])
        allf = np.concatenate([np.asarray(factors, dtype=np.float64), mf])
        order = np.lexsort((-allf, allv))
        allv, allf = allv[order], allf[order]
        first = np.r_[True, allv[1:] != allv[:-1]]
        return paint(indices, weights, num_joints, joint, allv[first], allf[first], **options)
    idx, w = paint(indices, weights, num_joints, joint, verts, factors, **options)
    if other in set(int(x) for x in options.get("locked", ())):
        return idx, w  # the other side's joint is locked: only this side changes
    uniq, first = np.unique(mv, return_index=True)
    fallback = options.pop("fallback", None)
    if fallback is not None:
        fallback = int(mirror_joints[fallback])
    return paint(idx, w, num_joints, other, uniq, mf[first], fallback=fallback, **options)
