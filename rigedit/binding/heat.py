"""Bone-heat skinning weights (Baran and Popovic 2007), robust to the meshes users bring.

For each deforming joint ``i`` the weights solve the heat equilibrium on the surface

    (L + M H) w_i = M H p_i

with ``L`` the clamped cotangent Laplacian (stiffness, :mod:`.laplacian`), ``M`` the lumped
mass, ``H = c / d^2`` where ``d`` is the distance from the vertex to its nearest *visible*
bone, and ``p_i = 1`` where joint ``i`` owns that bone (ties share: ``p = 1/n``, ``H = n c /
d^2``, as in Blender). A bone is visible from a vertex when the segment from the vertex to its
nearest point on the bone crosses no triangle (:mod:`.visibility`). All joints are solved as
one block right-hand side of one sparse Cholesky factorisation (CHOLMOD when scikit-sparse is
installed, SciPy's SuperLU otherwise).

What makes it robust where Blender is not:

- coincident vertices are welded first (glTF splits vertices at UV seams; left split, a
  seam would be a cut in the surface), degenerate and repeated triangles dropped;
- the operator is built per triangle with clamped cotangents, so non-manifold edges, open
  edges and slivers give a positive semi-definite matrix;
- the system is block-diagonal over connected parts, and only parts where some vertex sees a
  bone are solved; a part no bone can see (a loose accessory outside the body, a lone vertex
  behind a surface) takes inverse-distance weights from the nearest bones instead, and those
  vertices are reported (``result.fallback``), never left unweighted.
"""
from __future__ import annotations

import time
import warnings

import numpy as np
import scipy.sparse as sp

from . import laplacian as lap
from ..model.skinning import top_k_influences
from ..model.helper_joints import helper_joints
from ..progress import adapt
from .tails import branch_tails, deforming_joints, ik_chain_tails, infer_leaf_tails
from .visibility import SurfaceRays
from .distance import inverse_distance_weights, point_segment_distance

try:  # CHOLMOD: measured faster than SuperLU (see benchmarks/bench_weights.py)
    from sksparse.cholmod import cholesky as _cholmod
except ImportError:  # pragma: no cover - machines without scikit-sparse
    _cholmod = None

__all__ = ["heat_weights", "WeightsResult", "HeatWeightsWarning"]

# c in H = c / d^2. Baran and Popovic's 1 is half of Blender's in effect (its Laplacian is
# half the Laplace-Beltrami operator: 0.5 / area times the cotangent sum over 2), and artists
# blend neighbouring bones more tightly still: the error against the artists' weights of
# the shared characters is least for c between 3 and 4, flat around it (README).
C_HEAT = 4.0
TIE = 1e-4              # bones within this relative distance of the nearest share the vertex
MAX_ROUNDS = 8          # how many nearest bones to try before a vertex sees none
BEHIND = -0.1           # see ``behind`` in heat_weights
RING_BEHIND = 0.75      # see _visible
MIN_WEIGHT = 0.025      # influences below this (after top-K) are dropped (Blender: 0.025)
WELD = 1e-6             # weld distance, as a fraction of the bounding-box diagonal
CHUNK = 16384           # vertices per block of the distance computation


class HeatWeightsWarning(UserWarning):
    """Heat weights needed a fallback or found a suspicious skeleton."""


class WeightsResult(tuple):
    """``(indices, weights)`` that also carries what the method had to do.

    Unpacks like the plain tuple every weights method returns.

    Attributes
    ----------
    fallback : (N,) int64
        Vertices whose weights came from the nearest bones, because no bone was visible
        from any vertex of their connected part.
    timings : dict[str, float]
        Seconds per stage.
    tails : (J, 3) float64
        The bone tails used (inferred for leaves), NaN for joints with none.
    deform : (J,) bool
        The joints that could take weight.
    left_out : dict[str, str]
        Joints flagged deforming that took no weight, and why (an end marker, an IK or pole
        target, a twist or share bone, a carrier root, zero length).
    """

    def __new__(cls, indices, weights, **info):
        self = super().__new__(cls, (indices, weights))
        self.fallback = info.get("fallback", np.zeros(0, np.int64))
        self.timings = info.get("timings", {})
        self.tails = info.get("tails")
        self.deform = info.get("deform")
        self.left_out = info.get("left_out", {})
        return self


def _check_input(vertices, faces):
    vertices = np.asarray(vertices, dtype=np.float64)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or len(vertices) == 0:
        raise ValueError(f"expected vertices of shape (V, 3) with V > 0, got {vertices.shape}")
    bad = ~np.isfinite(vertices).all(axis=1)
    if bad.any():
        raise ValueError(f"expected finite vertex coordinates, got NaN or inf at {bad.sum()} "
                         f"vertices (first: {int(np.flatnonzero(bad)[0])})")
    if faces is None:
        raise ValueError("heat weights need the mesh's faces (faces=...), got none; "
                         "use method='idw' for a point cloud")
    faces = np.asarray(faces)
    if faces.size == 0:
        raise ValueError("heat weights need triangles, got a mesh with no faces; "
                         "use method='idw' for a point cloud")
    if faces.ndim != 2 or faces.shape[1] != 3 or not np.issubdtype(faces.dtype, np.integer):
        raise ValueError(f"expected faces of shape (F, 3) int, got {faces.shape} {faces.dtype}")
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise ValueError(f"expected face indices in [0, {len(vertices) - 1}], got "
                         f"{faces.min()}..{faces.max()}")
    return vertices, faces.astype(np.int64)


def _joint_distances(points, starts, ends, owners, joints, dist=None, seg=None,
                     seg_index=None):
    """Distance of each point to each joint (nearest of its segments) and that segment.

    Segments must be grouped by owner (as :meth:`Skeleton.bone_segments` returns them).
    With ``dist`` and ``seg`` given, only the columns of the joints in ``owners`` are
    recomputed, in place; ``seg_index`` maps these segments to their global indices.

    Returns
    -------
    dist : (N, J') float64
    seg : (N, J') int32
        Index into the segments of the nearest one per joint.
    """
    if dist is None:
        dist = np.empty((len(points), len(joints)))
        seg = np.empty((len(points), len(joints)), np.int32)
    first = np.flatnonzero(np.r_[True, owners[1:] != owners[:-1]])
    cols = np.searchsorted(joints, owners[first])
    if np.array_equal(cols, np.arange(cols[0], cols[0] + len(cols))):
        cols = slice(cols[0], cols[0] + len(cols))  # a slice writes without fancy indexing
    bounds = np.r_[first, len(owners)]
    multi = [g for g in range(len(first)) if bounds[g + 1] - bounds[g] > 1]
    gi = np.arange(len(owners)) if seg_index is None else np.asarray(seg_index)
    seg_first = gi[first].astype(np.int32)
    col_list = np.arange(dist.shape[1])[cols]
    for lo in range(0, len(points), CHUNK):
        d = point_segment_distance(points[lo:lo + CHUNK], starts, ends)
        dist[lo:lo + CHUNK, cols] = np.minimum.reduceat(d, first, axis=1)
        seg[lo:lo + CHUNK, cols] = seg_first
        for g in multi:  # joints with several bones (a hip): a few at most
            a, b = bounds[g], bounds[g + 1]
            seg[lo:lo + CHUNK, col_list[g]] = gi[a + d[:, a:b].argmin(axis=1)]
    return dist, seg


def _nearest_on_segment(points, starts, ends):
    seg = ends - starts
    l2 = np.einsum("ij,ij->i", seg, seg)
    t = np.einsum("ij,ij->i", points - starts, seg) / np.where(l2 > 0, l2, 1.0)
    return starts + np.clip(t, 0.0, 1.0)[:, None] * seg


def _factor_solve(A, B, solver="auto"):
    """Solve the SPD system ``A X = B`` for a block of right-hand sides; timings."""
    if solver not in ("auto", "cholmod", "splu"):
        raise ValueError(f"expected solver 'auto', 'cholmod' or 'splu', got {solver!r}")
    if solver == "cholmod" and _cholmod is None:
        raise ValueError("solver 'cholmod' needs scikit-sparse, which is not installed")
    t0 = time.perf_counter()
    if _cholmod is not None and solver != "splu":
        factor = _cholmod(A.tocsc())
        t1 = time.perf_counter()
        X = factor(B)
    else:
        from scipy.sparse.linalg import splu
        factor = splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                      options={"SymmetricMode": True})
        t1 = time.perf_counter()
        X = factor.solve(B)
    return np.asarray(X), t1 - t0, time.perf_counter() - t1


def heat_weights(vertices, skeleton, faces=None, max_influences=4, progress=None,
                 c=C_HEAT, min_weight=MIN_WEIGHT, front_only=False, normal_bias=False,
                 behind=BEHIND, infer_tails=True, operator="cotan", solver="auto",
                 use_numba=None, branches="children", helpers=True, own_part=True,
                 ik_chains=True):
    """Bone-heat weights of a triangle mesh (see the module notes).

    Parameters
    ----------
    vertices : (V, 3) float64
    skeleton : Skeleton
    faces : (F, 3) int
        Required: heat flows over the surface.
    max_influences : int
    progress : callable(fraction, stage), optional
        :mod:`rigedit.progress`'s protocol (stage ``"heat"``), called between the steps;
        :class:`rigedit.progress.Cancelled` (or any exception) raised by it stops the
        computation. The older ``progress(fraction)`` still works (deprecated).
    c : float
        Heat constant of ``H = c / d^2``.
    min_weight : float
        Influences below it are dropped after keeping the top ``max_influences``; the
        largest influence of a vertex is always kept.
    front_only : bool
        Count only surface crossings that enter the surface from outside (Blender's rule),
        rather than any crossing.
    normal_bias : bool
        Rank bones by Blender's ``d / (0.5 (cos + 1.001))``, which pushes away bones that lie
        in front of the vertex's normal, rather than by plain distance.
    behind : float
        A bone counts as visible only where its nearest point lies behind the surface:
        the cosine between the vertex normal and the direction to the bone is below this
        (2 turns the test off). A part of the mesh where no vertex sees a bone this way
        (an accessory outside the body, a part far from the skeleton) takes the fallback.
    infer_tails : bool
        Give tail-less leaf joints a tail (:mod:`.tails`); otherwise they are points.
    operator : {"cotan", "robust"}
        The clamped cotangent Laplacian (default), or the intrinsic Delaunay Laplacian of the
        ``robust-laplacian`` package when it is installed (measured slower, see the README).
    solver : {"auto", "cholmod", "splu"}
        CHOLMOD (scikit-sparse) when installed, else SciPy's SuperLU.
    use_numba : bool, optional
        Force the compiled or the numpy ray tests (default: compiled when available).
    branches : {"children", "centroid"}
        A tail-less joint with several children owns a segment to each child (default), or
        one bone toward their centroid (:func:`.tails.branch_tails`, Blender's importer's
        rule; measured better on the Mixamo character only, see the README).
    helpers : bool
        Leave out helper joints (:mod:`.helper_joints`: end markers, IK and pole targets,
        twist and share bones, carrier roots confirmed by the mesh); see
        :func:`.tails.deforming_joints`.

    Returns
    -------
    result : WeightsResult
        ``indices (V, K) int32, weights (V, K) float64`` with rows summing to 1, plus
        ``result.fallback`` and ``result.timings``.

    Raises
    ------
    ValueError
        NaN or infinite coordinates, no faces, face indices out of range.
    """
    report = adapt(progress, "heat")   # report(fraction): the stage is always "heat"
    timings = {}
    t0 = time.perf_counter()
    vertices, faces = _check_input(vertices, faces)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    diag = max(float(np.linalg.norm(hi - lo)), 1e-12)
    rep, wv = lap.weld(vertices, WELD * diag)
    wf = lap.clean_faces(rep[faces])
    n = len(wv)
    ncomp, label = lap.components(n, wf)
    timings["weld"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    if operator == "robust":
        import robust_laplacian
        L, M = robust_laplacian.mesh_laplacian(wv, wf.astype(np.int64))
        L, mass = L.tocsc(), M.diagonal()
    elif operator == "cotan":
        L, mass = lap.cotangent_laplacian(wv, wf)
    else:
        raise ValueError(f"expected operator 'cotan' or 'robust', got {operator!r}")
    timings["laplacian"] = time.perf_counter() - t0
    report(0.1)

    t0 = time.perf_counter()
    rays = SurfaceRays(wv, wf, use_numba=use_numba, parts=label[wf[:, 0]])
    normals = lap.vertex_normals(wv, wf, label)
    deform = deforming_joints(skeleton, wv, normals, helpers=helpers)
    tails = skeleton.tails
    if ik_chains:
        tails = ik_chain_tails(skeleton, deform, tails)
    if branches == "centroid":
        tails = branch_tails(skeleton, deform, tails)
    elif branches != "children":
        raise ValueError(f"expected branches 'children' or 'centroid', got {branches!r}")
    starts, ends, owners = skeleton.bone_segments(deform=deform, tails=tails)
    joints = np.unique(owners)
    dist, seg = _joint_distances(wv, starts, ends, owners, joints)
    if infer_tails:
        given = tails
        tails = infer_leaf_tails(skeleton, deform, wv,
                                 joints[dist.argmin(axis=1)], rays, tails=given)
        starts, ends, owners = skeleton.bone_segments(deform=deform, tails=tails)
        changed = np.isin(owners, np.flatnonzero(np.isfinite(tails[:, 0])
                                                 & ~np.isfinite(given[:, 0])))
        if changed.any():  # only the leaves that got a tail
            base = np.flatnonzero(changed)
            _joint_distances(wv, starts[base], ends[base], owners[base], joints, dist, seg,
                             seg_index=base)
    _warn_outside(skeleton, joints, starts, ends, owners, lo, hi)
    timings["distances"] = time.perf_counter() - t0
    report(0.2)

    t0 = time.perf_counter()
    rank = dist
    if normal_bias:
        rank = _normal_biased(wv, normals, starts, ends, seg, dist)

    ring = lap.OneRing(wv, wf, label)

    def test(verts, cols):
        return _visible(wv, normals, ring, verts, cols, seg, starts, ends, rays, front_only,
                        behind, 1e-4 * diag, label if own_part else None)
    pairs_v, pairs_j, best = _visible_nearest(wv, rank, dist, seg, starts, ends, report, test)
    timings["visibility"] = time.perf_counter() - t0

    ties = np.bincount(pairs_v, minlength=n)
    seen = np.isfinite(best)
    H = np.zeros(n)
    floor = 1e-3 * diag  # a bone through the surface must not make H infinite
    H[seen] = ties[seen] * c / np.maximum(best[seen], floor) ** 2
    solvable_part = np.zeros(ncomp, bool)
    solvable_part[label[seen]] = True
    solvable = solvable_part[label]
    k = min(max_influences, len(joints))
    idx = np.zeros((n, k), np.int32)
    val = np.zeros((n, k))

    t0 = time.perf_counter()
    if solvable.any():
        keep = np.flatnonzero(solvable)
        # A vertex in no triangle has no mass; give it a little so that H reaches it.
        m = np.where(mass > 0, mass, max(float(np.median(mass[mass > 0])) if (mass > 0).any()
                                          else 1.0, 1e-300) * 1e-3)
        mh = m * H
        A = (L + sp.diags(mh)).tocsr()[keep][:, keep]
        pos = np.full(n, -1)
        pos[keep] = np.arange(len(keep))
        inside = solvable[pairs_v]
        B = np.zeros((len(keep), len(joints)))
        np.add.at(B, (pos[pairs_v[inside]], pairs_j[inside]),
                  mh[pairs_v[inside]] / ties[pairs_v[inside]])
        timings["setup"] = time.perf_counter() - t0
        report(0.5)
        X, timings["factorisation"], timings["solve"] = _factor_solve(A, B, solver)
        report(0.9)
        t0 = time.perf_counter()
        np.clip(X, 0.0, None, out=X)
        ki, kv = top_k_influences(X, k)
        idx[keep], val[keep] = ki, kv
        # Rows of the heat solution sum to 1 on every solved part; one that does not
        # (round-off on a nearly cut-off vertex) joins the fallback rather than guess.
        weak = keep[X.max(axis=1) < 1e-6]
        solvable[weak] = False
    fallback_w = np.flatnonzero(~solvable)
    if len(fallback_w):
        fi, fv = inverse_distance_weights(dist[fallback_w], k)  # rigedit's idw rule
        idx[fallback_w], val[fallback_w] = joints[fi], fv
    idx[solvable] = joints[idx[solvable]]
    if k > 1 and min_weight > 0:
        small = val < min_weight
        small[:, 0] = False  # sorted: the largest stays
        val[small] = 0.0
        val /= val.sum(axis=1, keepdims=True)
    out_idx, out_w = idx[rep], val[rep]
    fallback = np.flatnonzero(~solvable[rep])
    timings["finish"] = time.perf_counter() - t0
    if len(fallback):
        warnings.warn(f"heat weights: {len(fallback)} of {len(vertices)} vertices are in parts "
                      f"of the mesh that no bone can see; they took weights from the nearest "
                      f"bones", HeatWeightsWarning, stacklevel=2)
    report(1.0)
    return WeightsResult(out_idx, out_w, fallback=fallback, timings=timings, tails=tails,
                         deform=deform, left_out=_left_out(skeleton, deform))


def _left_out(skeleton, deform):
    """{joint name: why} for the joints flagged deforming that take no weight."""
    reasons = helper_joints(skeleton.names, skeleton.parents, skeleton.bind_matrices[:, :3, 3])
    return {skeleton.names[j]: reasons[j] or "zero length"
            for j in np.flatnonzero(skeleton.deform & ~deform)}


def _visible_nearest(wv, rank, dist, seg, starts, ends, report, test):
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


def _visible(wv, normals, ring, verts, joints, seg, starts, ends, rays, front_only, behind,
             offset, label=None):
    """(N,) bool: joint ``joints[n]`` is visible from vertex ``verts[n]``: the segment to
    its nearest point crosses no triangle, and that point lies behind the vertex's surface:
    ``cos(normal, to bone) < behind``, and behind (or in) the planes of the vertex's own
    triangles that hold ``RING_BEHIND`` of their area (a bone in front of the skin is
    outside the body; at a sharp rim the averaged normal alone cannot tell)."""
    s = seg[verts, joints]
    target = _nearest_on_segment(wv[verts], starts[s], ends[s])
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


def _normal_biased(wv, normals, starts, ends, seg, dist):
    """Blender's ranking distance ``d / (0.5 (cos + 1.001))``, cos between the vertex
    normal and the direction from the bone to the vertex."""
    out = np.empty_like(dist)
    for j in range(dist.shape[1]):  # per joint column (tens)
        s = seg[:, j]
        d = wv - _nearest_on_segment(wv, starts[s], ends[s])
        cos = np.einsum("ij,ij->i", d, normals) / np.maximum(np.linalg.norm(d, axis=1), 1e-300)
        out[:, j] = dist[:, j] / (0.5 * (cos + 1.001))
    return out


def _warn_outside(skeleton, joints, starts, ends, owners, lo, hi):
    """Warn about deforming bones that lie wholly outside the mesh's bounding box."""
    pad = 0.01 * (hi - lo)
    out = np.zeros(len(joints), bool)
    for n, j in enumerate(joints):
        pts = np.concatenate([starts[owners == j], ends[owners == j]])
        out[n] = np.all(np.any((pts < lo - pad) | (pts > hi + pad), axis=1))
    if out.all():
        warnings.warn("heat weights: every bone lies outside the mesh's bounding box; is the "
                      "skeleton in the mesh's frame and units? Weights follow the nearest "
                      "visible bones", HeatWeightsWarning, stacklevel=3)
    elif out.any():
        names = ", ".join(skeleton.names[j] for j in joints[out][:5])
        warnings.warn(f"heat weights: {out.sum()} bones lie outside the mesh's bounding box "
                      f"({names})", HeatWeightsWarning, stacklevel=3)
