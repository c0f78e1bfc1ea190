"""Carried branches kept inside the mesh.

A carried branch (joints the search did not place: antlers the mesh lacks, a tail, ears,
toes) keeps the template's offsets from the placed joint it hangs from, so on a mesh shaped
differently it can stick out into the air (an elk's antlers on a cow's small horns), where
skin weights would pull the skin after it. Each branch, scaled about its base joint in the
template's proportions, is shortened until every one of its bones stays inside the mesh
(within ``TOLERANCE`` of the local radius); one that leaves the mesh even at ``SHORTEST`` of
its length has no geometry there, and collapses into the base joint's region instead (its
joints keep existing: clips name them; the caller stops them deforming).
"""
from __future__ import annotations

import re

import numpy as np
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from ..model.transforms import tangents
from .distance import surface_samples

__all__ = ["keep_inside", "describe_joints", "TOLERANCE", "SHORTEST", "COLLAPSED"]

#: How far a bone may leave the mesh, as a fraction of the local radius (the depth of the
#: branch's base joint, at least a cell), plus one cell: a leaf end (a toe tip, an ear tip)
#: often sits on the surface, and the field does not resolve parts thinner than a cell (the
#: bundled elk's antlers, half a cell deep, carried 2 cells off their place on its own mesh,
#: read up to 0.95 cell outside). How far out a point is comes from the nearest of a dense
#: sampling of the surface: the field itself only measures two cells outside.
TOLERANCE = 0.1
#: A branch that must be shorter than this fraction of the template's to stay inside is
#: taken as absent from the mesh, not short.
SHORTEST = 0.3
#: A collapsed branch reaches at most this fraction of the local radius from its base.
COLLAPSED = 0.5
_STEPS = np.linspace(1.0, SHORTEST, 15)
#: Turns (degrees) tried on a branch that leaves the mesh, about axes across it.
TURNS = (10.0, 20.0, 30.0, 40.0)
#: Turns are tried only on a branch kept at least this fraction of its length: a turned and
#: much shortened branch fits inside the body it hangs from (an elk's antlers, cut off its
#: mesh, turned 30 degrees and cut to 70% fit in its head), which is no geometry of its own.
TURN_LENGTH = 0.9


def _branches(parents, placed):
    """Carried subtrees hanging from a placed joint: (base, [joints, parent first]) pairs."""
    parents = np.asarray(parents)
    out, owner = [], {}
    for j in range(len(parents)):     # parents come before children
        p = parents[j]
        if placed[j] or p < 0:
            continue
        if placed[p]:
            owner[j] = len(out)
            out.append((int(p), [j]))
        elif p in owner:
            owner[j] = owner[p]
            out[owner[j]][1].append(j)
    return out


class _Outside:
    """How far points are outside the mesh (0 inside), (N, 3) -> (N,) float64."""

    def __init__(self, field, vertices, faces):
        self.field, self.vertices, self.faces = field, vertices, faces
        self.tree = None

    def __call__(self, points):
        out = np.zeros(len(points))
        far = self.field(points) <= 0.0
        if far.any():
            if self.tree is None:   # built only when some carried bone reaches outside
                # only vertices of faces: a stray one (a part cut off) is no surface
                used, faces = np.unique(self.faces, return_inverse=True)
                self.tree = cKDTree(surface_samples(self.vertices[used],
                                                    faces.reshape(-1, 3), self.field.h / 2.0,
                                                    np.random.default_rng(0)))
            out[far] = self.tree.query(points[far], workers=1)[0]
        return out


def _turns(direction):
    """Rotations to try on a branch pointing along ``direction`` (3,): none first, then
    ``TURNS`` degrees about 8 axes perpendicular to it, least first."""
    d = direction / max(np.linalg.norm(direction), 1e-300)
    u, v = tangents(d)
    out = [Rotation.identity()]
    for angle in np.radians(TURNS):
        for phi in np.linspace(0, 2 * np.pi, 8, endpoint=False):
            out.append(Rotation.from_rotvec(angle * (np.cos(phi) * u + np.sin(phi) * v)))
    return out


def keep_inside(field, positions, parents, placed, vertices, faces, mirror=None):
    """Turn, shorten or collapse the carried branches that leave the mesh.

    A branch leaving the mesh is first turned about its base (up to ``TURNS[-1]`` degrees:
    the carried direction follows the parent bone only, a head bent down or a scale guessed
    without the template's mesh sends antlers past the mesh's own), at its full length, then
    at shorter lengths (each with every turn); the least turn at the greatest length that
    stays inside is kept.

    Parameters
    ----------
    field : DistanceField
        The mesh's distance field (positive inside).
    positions : (J, 3) float64
        Every joint, carried ones included.
    parents : (J,) int
    placed : (J,) bool
        Joints placed by the search (never moved here).
    vertices : (V, 3) float64
    faces : (F, 3) int
        The mesh.
    mirror : (J,) int, optional
        Each joint's mirror image (-1: none): when one of two mirrored branches has no
        geometry, neither has.

    Returns
    -------
    positions : (J, 3) float64
        A copy with the branches moved.
    shortened : dict[int, float]
        Branch root joint -> the fraction of its template length kept (only branches cut).
    outside : list[int]
        Joints of the collapsed branches (no geometry there), in joint order.
    """
    out = np.array(positions, dtype=np.float64)
    away = _Outside(field, vertices, faces)
    fitted, collapsed = {}, {}       # branch root -> (joints, positions, kept fraction)
    for base, joints in _branches(parents, placed):
        b = out[base]
        offsets = out[joints] - b
        radius = max(float(field(b[None])[0]), field.h)
        # a base outside (in a part thinner than the field resolves): measured from there
        tol = float(away(b[None])[0]) + TOLERANCE * radius + field.h
        index = {j: k for k, j in enumerate(joints)}
        start_rows = [index.get(int(parents[j]), -1) for j in joints]   # -1: the base
        reach = np.linalg.norm(offsets, axis=1)
        longest = max(float(reach.max()), 1e-300)
        t = np.linspace(0.0, 1.0, int(np.ceil(2.0 * longest / field.h)) + 1)[:, None, None]

        def fits(pts):
            a = np.array([b if r < 0 else pts[r] for r in start_rows])
            samples = (a + t * (pts - a)).reshape(-1, 3)   # half a cell apart or closer
            return bool(np.all(away(samples) <= tol))

        turns = _turns(offsets[int(np.argmax(reach))])
        found = next(((float(s), turn) for s in _STEPS for turn in
                      (turns if s >= TURN_LENGTH else turns[:1])
                      if fits(b + s * turn.apply(offsets))), None)
        keep = min(SHORTEST, COLLAPSED * radius / longest)
        collapsed[joints[0]] = (joints, b + keep * offsets, keep)
        if found is not None:
            fitted[joints[0]] = (joints, b + found[0] * found[1].apply(offsets), found[0])
    shortened, outside = {}, []
    root_of = {j: root for root, (joints, _, _) in collapsed.items() for j in joints}
    for root, (joints, pts, keep) in collapsed.items():
        # one side of a mirror pair without geometry: the other fitting is chance (a hole's
        # edge, the body beside it), as meshes are near symmetric. Branches are mirrored when
        # any of their joints are (the bases of antlers lie too near the middle to count).
        twins = set() if mirror is None else {root_of.get(int(mirror[j]), root)
                                              for j in joints if mirror[j] >= 0}
        if root in fitted and all(t in fitted for t in twins):
            joints, pts, keep = fitted[root]
            if keep < 1.0:
                shortened[root] = keep
        else:
            outside += joints
        out[joints] = pts
    return out, shortened, sorted(outside)


def describe_joints(names):
    """Names in short runs: ``["antler_L_1", "antler_L_2", "antler_L_3", "ear_L"]`` ->
    ``"antler_L_1..3, ear_L"`` (consecutive numbered names of one stem joined)."""
    runs = []
    for name in names:
        m = re.fullmatch(r"(.*?)(\d+)", name)
        last = runs[-1] if runs else None
        if (m and last and last[0] == m.group(1) and last[2] is not None
                and int(m.group(2)) == last[2] + 1):
            last[2] = int(m.group(2))
            continue
        runs.append([m.group(1), int(m.group(2)), int(m.group(2))] if m else [name, None, None])
    return ", ".join(s if a is None else f"{s}{a}" if a == b else f"{s}{a}..{b}"
                     for s, a, b in runs)
