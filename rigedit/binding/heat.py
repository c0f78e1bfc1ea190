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

The steps live beside it: the bones and distances (:mod:`.heat_bones`), which bones each
vertex sees (:mod:`.heat_visibility`), and the system and its solve (:mod:`.heat_solve`).
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import numpy as np

from . import laplacian as lap
from ..model.skinning import top_k_influences
from ..model.helper_joints import helper_joints
from ..progress import adapt
from .distance import inverse_distance_weights
# CHUNK, MAX_ROUNDS, RING_BEHIND, TIE and _cholmod (None without CHOLMOD; the tests ask)
# were this module's before its steps were split off: kept importable from here
from .heat_bones import CHUNK, heat_bones  # noqa: F401
from .heat_solve import _cholmod, factor_solve, heat_system  # noqa: F401
from .heat_visibility import (MAX_ROUNDS, RING_BEHIND, TIE, normal_biased,  # noqa: F401
                              visible, visible_nearest)
from .visibility import SurfaceRays

__all__ = ["heat_weights", "WeightsResult", "HeatWeightsWarning"]

# c in H = c / d^2. Baran and Popovic's 1 is half of Blender's in effect (its Laplacian is
# half the Laplace-Beltrami operator: 0.5 / area times the cotangent sum over 2), and artists
# blend neighbouring bones more tightly still: the error against the artists' weights of
# the shared characters is least for c between 3 and 4, flat around it (README).
C_HEAT = 4.0
BEHIND = -0.1           # see ``behind`` in heat_weights
MIN_WEIGHT = 0.025      # influences below this (after top-K) are dropped (Blender: 0.025)
WELD = 1e-6             # weld distance, as a fraction of the bounding-box diagonal


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


@dataclass
class _Welded:
    """The mesh welded: ``rep`` (V,) each input vertex's welded one, ``wv`` (W, 3) and
    ``wf`` (F', 3) the welded vertices and clean triangles, ``ncomp`` connected parts and
    each welded vertex's ``label`` (W,), the input's bounding box ``lo``, ``hi`` (3,) and
    its diagonal ``diag``."""

    rep: np.ndarray
    wv: np.ndarray
    wf: np.ndarray
    ncomp: int
    label: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    diag: float


def _weld(vertices, faces):
    """The mesh with coincident vertices welded and degenerate triangles dropped."""
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    diag = max(float(np.linalg.norm(hi - lo)), 1e-12)
    rep, wv = lap.weld(vertices, WELD * diag)
    wf = lap.clean_faces(rep[faces])
    ncomp, label = lap.components(len(wv), wf)
    return _Welded(rep, wv, wf, ncomp, label, lo, hi, diag)


def _operator(wv, wf, operator):
    """``(L, mass)``: the stiffness matrix (W, W) and the lumped mass (W,) of ``operator``."""
    if operator == "robust":
        import robust_laplacian
        L, M = robust_laplacian.mesh_laplacian(wv, wf.astype(np.int64))
        return L.tocsc(), M.diagonal()
    if operator == "cotan":
        return lap.cotangent_laplacian(wv, wf)
    raise ValueError(f"expected operator 'cotan' or 'robust', got {operator!r}")


def heat_weights(vertices, skeleton, faces=None, max_influences=4, progress=None,
                 c=C_HEAT, min_weight=MIN_WEIGHT, front_only=False, normal_bias=False,
                 behind=BEHIND, infer_tails=True, operator="cotan", solver="auto",
                 use_numba=None, branches="children", helpers=True, own_part=True,
                 ik_chains=True):
    """Bone-heat weights of a triangle mesh (see the module notes).

    Over 80 lines for its docstring of seventeen options; the body is the steps in order,
    each timed (``result.timings``) and reported to ``progress``.

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
    mesh = _weld(vertices, faces)
    timings["weld"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    L, mass = _operator(mesh.wv, mesh.wf, operator)
    timings["laplacian"] = time.perf_counter() - t0
    report(0.1)

    t0 = time.perf_counter()
    rays = SurfaceRays(mesh.wv, mesh.wf, use_numba=use_numba, parts=mesh.label[mesh.wf[:, 0]])
    normals = lap.vertex_normals(mesh.wv, mesh.wf, mesh.label)
    bones = heat_bones(skeleton, mesh.wv, normals, rays, helpers=helpers, ik_chains=ik_chains,
                       branches=branches, infer_tails=infer_tails)
    _warn_outside(skeleton, bones.joints, bones.starts, bones.ends, bones.owners, mesh.lo,
                  mesh.hi)
    timings["distances"] = time.perf_counter() - t0
    report(0.2)

    t0 = time.perf_counter()
    pairs_v, pairs_j, best = _nearest_visible(mesh, normals, rays, bones, report, normal_bias,
                                              front_only, behind, own_part)
    timings["visibility"] = time.perf_counter() - t0

    ties = np.bincount(pairs_v, minlength=len(mesh.wv))
    H, solvable = _heat_and_solvable(mesh, best, ties, c)
    k = min(max_influences, len(bones.joints))
    idx, val, t0 = _solve_parts(L, mass, H, ties, pairs_v, pairs_j, solvable,
                                len(bones.joints), k, solver, report, timings)
    out_idx, out_w, fallback = _finish(mesh, bones, idx, val, solvable, k, min_weight)
    timings["finish"] = time.perf_counter() - t0
    if len(fallback):
        warnings.warn(f"heat weights: {len(fallback)} of {len(vertices)} vertices are in parts "
                      f"of the mesh that no bone can see; they took weights from the nearest "
                      f"bones", HeatWeightsWarning, stacklevel=2)
    report(1.0)
    return WeightsResult(out_idx, out_w, fallback=fallback, timings=timings, tails=bones.tails,
                         deform=bones.deform, left_out=_left_out(skeleton, bones.deform))


def _nearest_visible(mesh, normals, rays, bones, report, normal_bias, front_only, behind,
                     own_part):
    """The nearest visible joint(s) of every welded vertex
    (:func:`.heat_visibility.visible_nearest`): ``pairs_v, pairs_j`` (P,) and ``best`` (W,),
    the options as :func:`heat_weights` takes them."""
    rank = bones.dist
    if normal_bias:
        rank = normal_biased(mesh.wv, normals, bones.starts, bones.ends, bones.seg, bones.dist)
    ring = lap.OneRing(mesh.wv, mesh.wf, mesh.label)
    label = mesh.label if own_part else None

    def test(verts, cols):
        return visible(mesh.wv, normals, ring, verts, cols, bones.seg, bones.starts,
                       bones.ends, rays, front_only, behind, 1e-4 * mesh.diag, label)
    return visible_nearest(mesh.wv, rank, bones.dist, bones.seg, bones.starts, bones.ends,
                           report, test)


def _heat_and_solvable(mesh, best, ties, c):
    """``(H, solvable)``: ``ties c / d^2`` (W,) at the vertices that see a bone (``best``,
    the distance to it, finite), 0 elsewhere; and (W,) bool, the vertices of the parts
    where some vertex does."""
    seen = np.isfinite(best)
    H = np.zeros(len(mesh.wv))
    floor = 1e-3 * mesh.diag  # a bone through the surface must not make H infinite
    H[seen] = ties[seen] * c / np.maximum(best[seen], floor) ** 2
    solvable_part = np.zeros(mesh.ncomp, bool)
    solvable_part[mesh.label[seen]] = True
    return H, solvable_part[mesh.label]


def _solve_parts(L, mass, H, ties, pairs_v, pairs_j, solvable, n_joints, k, solver, report,
                 timings):
    """The heat solved on the ``solvable`` parts, its ``k`` largest influences kept.

    Returns ``idx`` (W, k) int32 joint *columns* and ``val`` (W, k) float64 (zeros outside
    the solved parts), and when the solve ended (the finish is timed from there). A vertex
    whose solution is all but 0 (round-off on a nearly cut-off vertex) joins the fallback:
    ``solvable`` is cleared there, in place. ``timings`` takes ``setup``,
    ``factorisation`` and ``solve``."""
    n = len(H)
    idx = np.zeros((n, k), np.int32)
    val = np.zeros((n, k))
    t0 = time.perf_counter()
    if solvable.any():
        keep = np.flatnonzero(solvable)
        A, B = heat_system(L, mass, H, ties, pairs_v, pairs_j, solvable, n_joints)
        timings["setup"] = time.perf_counter() - t0
        report(0.5)
        X, timings["factorisation"], timings["solve"] = factor_solve(A, B, solver)
        report(0.9)
        t0 = time.perf_counter()
        np.clip(X, 0.0, None, out=X)
        ki, kv = top_k_influences(X, k)
        idx[keep], val[keep] = ki, kv
        # Rows of the heat solution sum to 1 on every solved part; one that does not
        # (round-off on a nearly cut-off vertex) joins the fallback rather than guess.
        weak = keep[X.max(axis=1) < 1e-6]
        solvable[weak] = False
    return idx, val, t0


def _finish(mesh, bones, idx, val, solvable, k, min_weight):
    """The influences of every input vertex: the fallback (inverse-distance weights from
    the nearest bones) where the heat was not solved, columns turned into joints, those
    under ``min_weight`` dropped (the largest kept). Returns ``(indices (V, k) int32,
    weights (V, k) float64, fallback (N,) int64)``; ``idx`` and ``val`` are changed."""
    fallback_w = np.flatnonzero(~solvable)
    if len(fallback_w):
        fi, fv = inverse_distance_weights(bones.dist[fallback_w], k)  # rigedit's idw rule
        idx[fallback_w], val[fallback_w] = bones.joints[fi], fv
    idx[solvable] = bones.joints[idx[solvable]]
    if k > 1 and min_weight > 0:
        small = val < min_weight
        small[:, 0] = False  # sorted: the largest stays
        val[small] = 0.0
        val /= val.sum(axis=1, keepdims=True)
    return idx[mesh.rep], val[mesh.rep], np.flatnonzero(~solvable[mesh.rep])


def _left_out(skeleton, deform):
    """{joint name: why} for the joints flagged deforming that take no weight."""
    reasons = helper_joints(skeleton.names, skeleton.parents, skeleton.bind_matrices[:, :3, 3])
    return {skeleton.names[j]: reasons[j] or "zero length"
            for j in np.flatnonzero(skeleton.deform & ~deform)}


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
