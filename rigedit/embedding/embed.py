"""``embed_skeleton``: a template skeleton fitted inside a mesh (Baran and Popovic 2007).

Stages (each timed in ``Embedding.seconds``): the reduced template, the distance field,
the medial surface and the spheres on it, the graph on their centres, the discrete
best-first search, the continuous refinement (:mod:`rigedit.embedding.fit`) and the
placement of the carried joints.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..binding.laplacian import face_areas
from ..progress import adapt, scaled
from .distance import distance_field
from .fit import W_SCALE_FIRM, W_SCALE_WEAK, fit_joints
from .graph import medial_graph
from .hints import HintError, check_hints
from .inside import keep_inside
from .legs import LEG_TOP, leg_top_heights, lower_leg_tops, template_leg_top
from .medial import medial_cells, pack_spheres
from .place import place_carried, place_chains
from .search import discrete_embedding
from .tails import extend_tails
from .template import reduce_template

__all__ = ["Embedding", "EmbeddingError", "HintError", "embed_skeleton"]


#: An embedding costing more than this per reduced bone is refused: a fair fit costs well
#: under 1 per bone (0.02-2.3 in all on the test meshes), a blob's forced one 20 or more.
MAX_COST_PER_BONE = 3.0


class EmbeddingError(ValueError):
    """Nothing in the mesh fits the template; the message says what is missing."""


@dataclass
class Embedding:
    """A template embedded in a mesh.

    Attributes
    ----------
    positions : (J, 3) float64
        Every template joint, template order, in the mesh's frame and units.
    seconds : dict[str, float]
        Wall seconds per stage.
    cost : float
        Penalty of the discrete embedding (lower is better; ~1 per reduced bone is a fair fit).
    placed : list[str]
        Joints placed from the mesh (by the search, and inner joints of embedded chains);
        the others are carried from the template.
    scale : float
        Mesh units per template unit found.
    spheres : (S, 4) float64
        The medial spheres (centre, radius), for display and debugging.
    shortened : dict[str, float]
        Carried branches (by their first joint) shortened to stay inside the mesh -> the
        fraction of the template's length kept.
    outside : list[str]
        Joints of carried branches with no geometry around them (they would stick out of
        the mesh even when short): collapsed into their base joint's region; they should
        not deform the skin.
    """

    positions: np.ndarray
    seconds: dict = field(default_factory=dict)
    cost: float = 0.0
    placed: list = field(default_factory=list)
    scale: float = 1.0
    spheres: np.ndarray = None
    shortened: dict = field(default_factory=dict)
    outside: list = field(default_factory=list)


def _check_mesh(vertices, faces):
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or len(vertices) < 4:
        raise EmbeddingError(f"expected (V, 3) vertices with V >= 4, got shape {vertices.shape}")
    if not np.all(np.isfinite(vertices)):
        raise EmbeddingError("expected finite vertex coordinates, got NaN or inf")
    if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) < 4:
        raise EmbeddingError(f"expected (F, 3) triangles with F >= 4, got shape {faces.shape}")
    if not np.issubdtype(faces.dtype, np.integer) or faces.min() < 0 or faces.max() >= len(
            vertices):
        raise EmbeddingError(f"expected face indices in [0, {len(vertices) - 1}], got "
                             f"{faces.min()}..{faces.max()}")
    if np.ptp(vertices, axis=0).min() <= 0:
        raise EmbeddingError("expected a mesh with volume, got a flat one")
    return vertices, faces.astype(np.int64)


def _frame(vertices, faces):
    """Floor, height, middle plane (area-weighted centroid x) and surface area of the mesh."""
    tri = vertices[faces]
    area = face_areas(vertices, faces)
    centre = tri.mean(axis=1)
    plane = float(np.average(centre[:, 0], weights=area)) if area.sum() > 0 else float(
        vertices[:, 0].mean())
    return {"floor": float(vertices[:, 1].min()), "height": float(np.ptp(vertices[:, 1])),
            "plane_x": plane, "area": float(area.sum())}


def _pin(positions, pins):
    """``positions`` (J, 3) with the pinned joints put at their points."""
    out = np.array(positions, dtype=np.float64)
    for j, point in pins.items():
        out[j] = point
    return out


def _leg_pinned(reduced, pins):
    """Whether a pinned joint is one :func:`lower_leg_tops` would move (hips, thighs, knees,
    spine)."""
    hips = {reduced.joints[reduced.parent[r]] for r in range(1, len(reduced.joints))
            if len(reduced.chains[r]) > 2}
    moved = set()
    for r in range(1, len(reduced.joints)):
        if reduced.joints[reduced.parent[r]] in hips:
            moved.update(reduced.chains[r][:-1])
    return bool(moved & set(pins))


def embed_skeleton(vertices, faces, template, progress=None, template_mesh=None, hints=None):
    """Embed a template skeleton in a closed (or nearly closed) triangle mesh.

    Parameters
    ----------
    vertices : (V, 3) float64
        In rigedit's frame (+Y up, facing +Z), any scale and position.
    faces : (F, 3) int
    template : rigedit.Skeleton
        Its rest pose gives the template's joint positions.
    progress : callable(fraction, stage), optional
        :mod:`rigedit.progress`'s protocol: called with the fraction done (0..1) and the
        stage ``"embed"``; raising :class:`rigedit.progress.Cancelled` (or anything) cancels
        (the exception propagates). The older ``progress(fraction)`` still works
        (deprecated).
    template_mesh : ((V, 3) float64, (F, 3) int), optional
        The template's own mesh at its rest pose (a bundled character's, a .glb's). With it
        the scale comes from the two heights and the template's ground is known; without it
        both are estimated from the skeleton alone.
    hints : dict[str, (3,) float], optional
        Template joint name -> where it must be, in the frame of ``vertices``: those joints
        are put exactly there and the search places the others around them
        (:mod:`rigedit.embedding.hints`).

    Returns
    -------
    Embedding

    Raises
    ------
    EmbeddingError
        When the mesh is unusable or nothing in it fits the template; the message names the
        part of the template that found no place.
    HintError
        (a ValueError) naming the joint of a hint that is not the template's or lies
        outside the mesh.
    """
    report = adapt(progress, "embed")
    stage = _Stages(report)
    report(0.0)
    vertices, faces = _check_mesh(vertices, faces)
    try:
        reduced = stage("template", 0.02, reduce_template, template, template_mesh)
    except ValueError as exc:
        raise EmbeddingError(str(exc)) from None
    check_hints(hints, template.names)     # unknown names before the long stages
    field_ = stage("distance field", 0.3, distance_field, vertices, faces)
    if not field_.inside.any():
        raise EmbeddingError("the mesh encloses no volume (is it closed?)")
    pins = check_hints(hints, template.names, field_)
    cells = stage("medial surface", 0.4, medial_cells, field_)
    spheres = stage("spheres", 0.45, pack_spheres, *cells, field_.h)
    graph = stage("graph", 0.55, medial_graph, field_, *spheres)
    frame = _frame(vertices, faces)
    frame["cell"] = field_.h
    scale = _first_scale(reduced, frame)
    sub = scaled(report, 0.55, 0.8) if progress is not None else None
    found = _search(stage, graph, reduced, template, frame, scale, sub, field_, pins)
    positions, ok, paths = _graph_positions(graph, reduced, found.vertex, pins)
    hold = W_SCALE_FIRM if np.isfinite(reduced.height) else W_SCALE_WEAK
    chains = _pin(place_chains(reduced, positions, paths, scale=scale), pins)
    out, scale = stage("refinement", 0.95, fit_joints, field_, reduced, chains, scale,
                       frame["floor"], hold, graph.points, frame["plane_x"], pins)
    out = _thighs_apart(field_, reduced, out, frame["plane_x"], template_mesh, pins)
    # hinted carried joints first, so that the carried joints below them follow
    out = stage("placement", 1.0, place_carried, reduced, _pin(out, pins), scale,
                frame["floor"])
    placed_mask = np.zeros(len(out), dtype=bool)
    for r in np.flatnonzero(ok):
        placed_mask[reduced.chains[r][1:] if r else [reduced.joints[0]]] = True
    placed_mask[list(pins)] = True
    t0 = time.perf_counter()
    out, cut, gone = keep_inside(field_, out, reduced.parents, placed_mask, vertices, faces,
                                 reduced.mirror_all)
    stage.seconds["placement"] += time.perf_counter() - t0
    return Embedding(out, stage.seconds, float(found.cost),
                     [template.names[j] for j in np.flatnonzero(placed_mask)], float(scale),
                     np.c_[graph.points, graph.radii],
                     {template.names[j]: s for j, s in cut.items()},
                     [template.names[j] for j in gone])


class _Stages:
    """Runs the embedding's stages, each timed into ``seconds`` (by name) and reported to
    ``report`` (its fraction done when it ends)."""

    def __init__(self, report):
        self.report = report
        self.seconds = {}

    def __call__(self, name, fraction, fn, *args, **kw):
        t0 = time.perf_counter()
        out = fn(*args, **kw)
        self.seconds[name] = time.perf_counter() - t0
        self.report(fraction)
        return out


def _first_scale(reduced, frame):
    """Mesh units per template unit, from the two heights and areas (a template with its
    own mesh) or from the mesh's height against the template's joints' (without)."""
    kept = reduced.rest[~reduced.carried]
    if np.isfinite(reduced.height):
        # Height says how big a standing character is but shrinks in a crouch; surface area
        # does not change with the pose but grows with girth: take the geometric mean.
        return np.sqrt(frame["height"] / max(reduced.height, 1e-12)
                       * np.sqrt(frame["area"] / max(reduced.area, 1e-300)))
    return frame["height"] / max(np.max(kept[:, 1]) - reduced.floor, 1e-12) / 1.1


def _search(stage, graph, reduced, template, frame, scale, progress, field_, pins):
    """The discrete embedding (:func:`.search.discrete_embedding`, timed as ``search``),
    refused (:class:`EmbeddingError` naming the part of the template that found no place)
    when the graph is too small, nothing fits, or the best fit costs over
    :data:`MAX_COST_PER_BONE` per reduced bone; its tails extended."""
    if len(graph.points) < len(reduced.joints):
        raise EmbeddingError(
            f"no place found for the template's {reduced.label(template, 1)}: the mesh has "
            f"{len(graph.points)} medial spheres, expected at least {len(reduced.joints)} "
            "(is it a blob without limbs?)")
    t0 = time.perf_counter()
    found = discrete_embedding(graph, reduced, frame, scale, progress, field_, pins)
    stage.seconds["search"] = time.perf_counter() - t0
    stage.report(0.8)
    if found.vertex is None:
        raise EmbeddingError(f"no place found for the template's "
                             f"{reduced.label(template, found.failed)}")
    # Chains through a hint are where the user said, however far from the template's pose
    # (a deep crouch): their cost does not count against the fit (the others' does).
    hinted = np.array([bool(set(reduced.chains[r] if r else [reduced.joints[0]]) & set(pins))
                       for r in range(len(reduced.joints))])
    if found.cost - found.parts[hinted].sum() > MAX_COST_PER_BONE * max(
            len(reduced.joints) - 1, 1):
        worst = int(np.argmax(np.where(hinted, -np.inf, found.parts)))
        raise EmbeddingError(
            f"no place found for the template's {reduced.label(template, worst)}: the best "
            f"embedding costs {found.cost:.0f}, a fitting one under "
            f"{MAX_COST_PER_BONE * max(len(reduced.joints) - 1, 1):.0f} (is the mesh a blob "
            "without limbs, or posed far from the template?)")
    found.vertex = extend_tails(graph, reduced, found.vertex)
    return found


def _graph_positions(graph, reduced, vertex, pins):
    """The reduced joints where the search put them (pinned ones at their pins):
    ``positions`` (R, 3) (NaN where carried), ``ok`` (R,) bool (placed) and ``paths``, per
    reduced joint the graph's path (K, 3) from its parent's place to its own (None for the
    root and carried joints)."""
    positions = np.full((len(reduced.joints), 3), np.nan)
    ok = vertex >= 0
    positions[ok] = graph.points[vertex[ok]]
    paths = [None] + [graph.points[graph.path(vertex[reduced.parent[r]], vertex[r])]
                      if ok[r] else None for r in range(1, len(ok))]
    for r, j in enumerate(reduced.joints):
        if j in pins and ok[r]:
            positions[r] = pins[j]
    return positions, ok, paths


def _thighs_apart(field_, reduced, out, plane_x, template_mesh, pins):
    """A deep trunk lifts the hips' sphere centre: the thighs go where the legs part
    (:func:`.legs.lower_leg_tops`), but not when the user pinned a leg's joints (they said
    where the legs are). ``out`` (J, 3) -> (J, 3)."""
    above = LEG_TOP if template_mesh is None else template_leg_top(reduced, *template_mesh)
    tops = leg_top_heights(field_, reduced, out, plane_x, above)
    if not _leg_pinned(reduced, pins):
        out = lower_leg_tops(reduced, out, tops)
    return out
