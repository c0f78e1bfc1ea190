"""The template skeleton reduced for the search: which joints are embedded, which carried.

* Non-deforming roots (a ground-level ``root`` that only carries the character) and short
  tips are **carried**: placed afterwards from the template, relative to the embedded chain
  they hang from and scaled to it. A joint is a short tip when its bone plus the longest
  path below it is under ``SHORT`` of the template's size (ears, jaw, fingers, toes, the end
  of a tail): a mesh may not model them, and they are too small for the medial graph.
* The remaining (kept) joints of degree other than two form the **reduced skeleton**; each
  reduced bone stands for a chain of template bones, whose inner joints are placed along
  the embedded chain at the end.
* A reduced leaf whose chain (from the junction it leaves) is shorter than ``REQUIRED`` of
  the longest such chain is **optional**: the search may carry it instead, at a price (a
  tail the mesh lacks, antlers on a cow). Longer ones (arms, legs) must be found.
* Mirror pairs (left/right) are found by geometry: a reduced joint whose reflection across
  the template's middle plane (x = root x) lands on another one.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..binding.laplacian import face_areas

__all__ = ["ReducedTemplate", "reduce_template", "SHORT", "REQUIRED"]

SHORT = 0.1
REQUIRED = 0.5
#: Joints of a middle-plane tip chain that make it a tail (see ``_tails``).
TAIL_JOINTS = 3
#: Height of a standing template's lowest embedded joints (ankles, hooves) above its ground,
#: as a fraction of the embedded joints' height span: about 6% on the bundled characters,
#: CesiumMan and RiggedFigure alike. A template does not say where its ground is (a BVH's
#: hips sit at the origin), so the ground is put this far below its lowest joint.
ANKLE_HEIGHT = 0.065


@dataclass
class ReducedTemplate:
    """The template as the search sees it.

    Attributes
    ----------
    rest : (J, 3) float64
        Model-space rest positions of every template joint.
    parents : (J,) int
        The template's parent indices.
    size : float
        Diagonal of the bounding box of the deforming joints.
    floor : float
        Ground height of the template: its mesh's lowest point when given, else estimated
        (see ``ANKLE_HEIGHT``).
    height, area : float
        Height and surface area of the template's mesh (NaN without one).
    joints : (R,) int
        Template indices of the reduced joints, parent before child.
    parent : (R,) int
        Reduced parent of each (index into ``joints``; -1 for the reduced root).
    chains : list of list of int
        For reduced joint r > 0, the template joints from its reduced parent to it, both ends
        included.
    chain_length : (R,) float64
        Summed template bone length of each chain (0 for the root).
    optional : (R,) bool
        The joint (with all below it) may be carried instead of embedded.
    mirror : (R,) int
        The reduced joint it mirrors (-1: none, or itself on the middle plane).
    carried : (J,) bool
        Template joints never embedded.
    mirror_all : (J,) int
        Every template joint's mirror image (-1: none; -2: on the middle plane).
    tail : (R,) bool
        The reduced joint ends a tail (see ``_tails``): optional, its length weakly held.
    """

    rest: np.ndarray
    parents: np.ndarray
    size: float
    floor: float
    height: float
    area: float
    joints: np.ndarray
    parent: np.ndarray
    chains: list
    chain_length: np.ndarray
    optional: np.ndarray
    mirror: np.ndarray
    carried: np.ndarray
    mirror_all: np.ndarray = None
    tail: np.ndarray = None

    def label(self, skeleton, r):
        """A human name for reduced joint ``r``'s chain ("left arm (LeftHand)")."""
        name = skeleton.names[self.joints[r]]
        x = self.rest[self.joints[r], 0] - self.rest[self.joints[0], 0]
        side = "" if abs(x) < 0.02 * self.size else ("left " if x > 0 else "right ")
        tip = self.rest[self.joints[r]] - self.rest[self.joints[self.parent[r]]] if r else 0
        if r == 0:
            kind = "root"
        elif len(np.flatnonzero(self.parent == r)) > 0:
            kind = "branching joint"
        elif np.ndim(tip) and abs(tip[1]) > np.hypot(tip[0], tip[2]) and tip[1] < 0:
            kind = "leg"
        elif side:
            kind = "arm or limb"
        else:
            kind = "head, neck or tail"
        return f"{side}{kind} ({name})"


def reduce_template(skeleton, mesh=None):
    """Reduce ``skeleton`` (a :class:`rigedit.Skeleton`) for the embedding.

    Parameters
    ----------
    skeleton : rigedit.Skeleton
        Its rest pose gives the joint positions.
    mesh : ((V, 3) float64, (F, 3) int), optional
        The template's own mesh at that rest pose: its ground and height are then known
        instead of estimated.

    Returns
    -------
    ReducedTemplate

    Raises
    ------
    ValueError
        When the template has no deforming joint or too few to embed (fewer than two).
    """
    rest = skeleton.forward(skeleton.rest_local_matrices())[:, :3, 3].copy()
    parents = skeleton.parents
    deform = np.asarray(skeleton.deform, dtype=bool)
    if not deform.any():
        raise ValueError("the template has no deforming joint to embed")
    lo, hi = rest[deform].min(axis=0), rest[deform].max(axis=0)
    size = float(np.linalg.norm(hi - lo))
    bone, tip = _bones_and_tips(rest, parents, size)
    tails = _tails(rest, parents, tip, size)
    tip &= ~tails
    # a root is carried when it does not deform (a ground-level "root" joint)
    carried = tip | ((parents < 0) & ~deform)
    kept = np.flatnonzero(~carried)
    if len(kept) < 2:
        raise ValueError(f"the template has {len(kept)} joint(s) long enough to embed; "
                         "expected at least two")
    reduced, parent, chains, length = _reduced_tree(parents, kept, bone)
    optional = _optional(parent, length)
    mirror = _mirror(rest[reduced], rest[reduced[0]], size)
    mirror_all = _mirror(rest, rest[reduced[0]], size)
    middle = np.abs(rest[:, 0] - rest[reduced[0], 0]) < 0.02 * size
    mirror_all[(mirror_all < 0) & middle] = -2
    kept_y = rest[kept, 1]
    floor = float(kept_y.min() - ANKLE_HEIGHT * np.ptp(kept_y))
    height = area = np.nan
    if mesh is not None:
        verts = np.asarray(mesh[0], dtype=np.float64)
        floor, height = float(verts[:, 1].min()), float(np.ptp(verts[:, 1]))
        area = surface_area(verts, mesh[1])
    return ReducedTemplate(rest, parents.copy(), size, floor, height, area, np.asarray(reduced),
                           parent, chains, length, optional, mirror, carried, mirror_all,
                           tails[reduced] & optional)


def _bones_and_tips(rest, parents, size):
    """``(bone, tip)``: each joint's bone length (J,) and whether it is a short tip (J,)
    bool: below a tip, or its bone plus the longest path below it under :data:`SHORT` of
    ``size``."""
    n = len(parents)
    bone = np.zeros(n)
    has = parents >= 0
    bone[has] = np.linalg.norm(rest[has] - rest[parents[has]], axis=1)
    reach = np.zeros(n)  # longest path from a joint down to a leaf below it
    for j in range(n - 1, 0, -1):
        p = parents[j]
        if p >= 0:
            reach[p] = max(reach[p], reach[j] + bone[j])
    tip = np.zeros(n, dtype=bool)
    for j in range(n):
        p = parents[j]
        tip[j] = p >= 0 and (tip[p] or bone[j] + reach[j] < SHORT * size)
    return bone, tip


def _reduced_tree(parents, kept, bone):
    """The reduced skeleton of the ``kept`` joints: those of degree other than two among
    them (and their root), each with its reduced parent and the chain of template joints
    between.

    Returns
    -------
    reduced : list of int
        Template indices, parent before child.
    parent : (R,) int
        Reduced parent of each (-1 for the root).
    chains : list of list of int
        For r > 0, the template joints from its reduced parent to it, both ends included.
    length : (R,) float64
        Summed ``bone`` length of each chain.

    Raises
    ------
    ValueError
        When the kept joints form more than one tree.
    """
    kept_set = set(kept.tolist())
    kept_children = {j: [c for c in np.flatnonzero(parents == j) if c in kept_set]
                     for j in kept}
    kept_parent = {}
    for j in kept:
        p = parents[j]
        while p >= 0 and p not in kept_set:
            p = parents[p]
        kept_parent[j] = p
    roots = [j for j in kept if kept_parent[j] < 0]
    if len(roots) != 1:
        raise ValueError(f"the template's embedded joints form {len(roots)} trees; expected one")
    degree = {j: len(kept_children[j]) + (kept_parent[j] >= 0) for j in kept}
    reduced = [j for j in kept if degree[j] != 2 or j == roots[0]]
    index = {j: r for r, j in enumerate(reduced)}
    parent = np.full(len(reduced), -1)
    chains = [[]]
    length = np.zeros(len(reduced))
    for r, j in enumerate(reduced[1:], start=1):
        chain = [j]
        p = kept_parent[j]
        while p not in index:
            chain.append(p)
            p = kept_parent[p]
        chain.append(p)
        parent[r] = index[p]
        chains.append(chain[::-1])
        length[r] = sum(bone[c] for c in chain[:-1])
    return reduced, parent, chains, length


def surface_area(vertices, faces):
    """Total area of a triangle mesh."""
    return float(face_areas(vertices, faces).sum())


def _tails(rest, parents, tip, size):
    """(J,) bool: short tip chains that are tails, to embed (as optional branches) rather
    than carry.

    A tail is an unbranched chain of at least ``TAIL_JOINTS`` joints on the middle plane,
    hanging from a joint that is not a tip. Tails vary most between characters (a pug's
    stub, a horse's long arc) and a mesh shows them well; carried at the template's length,
    the Quaternius horse's four tail joints sat 3.5-6.9% of its size off its artist's. A jaw
    (one joint), ears and antlers (off the plane) stay carried.
    """
    n = len(parents)
    root_x = rest[np.flatnonzero(parents < 0)[0], 0] if (parents < 0).any() else 0.0
    children = [np.flatnonzero(parents == j) for j in range(n)]
    out = np.zeros(n, dtype=bool)
    for j in range(n):
        p = parents[j]
        if not tip[j] or p < 0 or tip[p]:
            continue
        chain = [j]
        while len(children[chain[-1]]) == 1:
            chain.append(int(children[chain[-1]][0]))
        if len(children[chain[-1]]) or len(chain) < TAIL_JOINTS:
            continue
        if np.all(np.abs(rest[chain, 0] - root_x) < 0.02 * size):
            out[chain] = True
    return out


def _optional(parent, length):
    """Reduced leaves whose chain from the nearest branching joint is short are optional."""
    r = len(parent)
    children = [np.flatnonzero(parent == k) for k in range(r)]
    # length from the branching joint each leaf chain leaves (through degree-2 reduced joints)
    run = np.zeros(r)
    for k in range(1, r):
        p = parent[k]
        run[k] = length[k] + (run[p] if p > 0 and len(children[p]) == 1 else 0.0)
    leaves = [k for k in range(1, r) if len(children[k]) == 0]
    longest = max((run[k] for k in leaves), default=0.0)
    optional = np.zeros(r, dtype=bool)
    for k in leaves:
        if run[k] < REQUIRED * longest:
            optional[k] = True
            p = parent[k]  # a whole unbranched run is optional with its leaf
            while p > 0 and len(children[p]) == 1:
                optional[p] = True
                p = parent[p]
    return optional


def _mirror(points, root, size):
    """Index of each point's mirror image across the plane x = root x (-1: none)."""
    mirrored = points.copy()
    mirrored[:, 0] = 2.0 * root[0] - mirrored[:, 0]
    d = np.linalg.norm(mirrored[:, None, :] - points[None, :, :], axis=2)
    out = np.full(len(points), -1)
    for i in range(len(points)):
        j = int(np.argmin(d[i]))
        if j != i and d[i, j] < 0.05 * size and abs(points[i, 0] - root[0]) > 0.02 * size:
            out[i] = j
    return out
