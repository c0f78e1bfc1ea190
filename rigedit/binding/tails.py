"""Bone segments for automatic weights: which joints deform, and tails for tail-less leaves.

Formats such as glTF and BVH give joints but no bone ends, so a leaf joint (a head, a hand
without fingers, a toe) would be a single point and its influence a ball. Its tail is
inferred from the part of the mesh it would own:

1. the leaf's *region* is the set of vertices whose nearest bone segment is that leaf's
   point (every other bone kept as a segment);
2. the direction runs from the joint to the centroid of that region; when the region has
   fewer than ``MIN_REGION`` vertices or its centroid is too close to the joint to give a
   direction, the parent bone's direction is used instead;
3. the length is ``REACH`` (0.8) of the farthest projection of the region's vertices on that
   direction (without a region: half the parent bone's length);
4. clipped to the mesh: at most ``REACH`` of the distance to the first surface crossing
   along the direction, so the tail stays inside the body.

Joints that take no weight: those flagged ``deform`` false, a joint whose every bone has zero
length (a helper at the same place as its child), and a root *carrier*: a root at the model
origin with one child whose bone lies mostly outside the body (a character standing on the
ground with its root between the feet; "outside" is judged by the normal of the nearest
vertex at ten points along the bone).
"""
from __future__ import annotations

import numpy as np

from ..model.helper_joints import CARRIER, carrier_candidates, helper_joints

__all__ = ["deforming_joints", "infer_leaf_tails", "branch_tails", "ik_chain_tails"]

REACH = 0.8
MIN_REGION = 3


def deforming_joints(skeleton, vertices, normals, helpers=True):
    """(J,) bool: joints that may take weight.

    Parameters
    ----------
    skeleton : Skeleton
    vertices : (V, 3) float64
    normals : (V, 3) float64
        Outward vertex normals (:func:`rigedit.binding.laplacian.vertex_normals`); the mesh is
        the scale of "zero length" and the carrier test's judge of inside.
    helpers : bool
        Leave out the helper joints :func:`rigedit.model.helper_joints.helper_joints` finds
        (end markers, IK and pole targets, twist and share bones), and test its carrier
        candidates against the mesh; otherwise only a root at the origin with one child is
        tested as a carrier.
    """
    heads = skeleton.bind_matrices[:, :3, 3]
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    scale = max(float(np.linalg.norm(hi - lo)), 1e-12)
    tiny = 1e-6 * scale
    deform = skeleton.deform.copy()
    for j in np.flatnonzero(deform):
        kids = skeleton.children(j)
        tail = skeleton.tails[j]
        if np.all(np.isfinite(tail)):
            ends = tail[None]
        elif len(kids):
            ends = heads[kids]
        else:
            continue  # a leaf: gets an inferred tail
        if np.all(np.linalg.norm(ends - heads[j], axis=1) < tiny):
            deform[j] = False
    if helpers:
        reasons = helper_joints(skeleton.names, skeleton.parents, heads)
        deform &= (reasons == "") | (reasons == CARRIER)
        roots = carrier_candidates(skeleton.names, skeleton.parents, heads)
    else:
        roots = [j for j in np.flatnonzero(skeleton.parents < 0)
                 if np.linalg.norm(heads[j]) < tiny and len(skeleton.children(j)) == 1]
    for j in roots:
        kids = skeleton.children(j)
        if not deform[j] or not len(kids):
            continue
        # A carrier's bones (to each child) lie mostly outside the body: a root on the
        # ground between the feet, not a hip root inside the pelvis.
        t = np.linspace(0.05, 0.95, 10)[None, :, None]
        along = (heads[j] + t * (heads[kids] - heads[j])[:, None, :]).reshape(-1, 3)
        if _inside_fraction(along, vertices, normals) < 0.5:
            deform[j] = False
    if not skeleton.deform.any():
        raise ValueError("expected at least one deforming joint, got none")
    if not deform.any():  # the rules above removed every joint: keep the flagged ones
        deform = skeleton.deform.copy()
    return deform


def _inside_fraction(points, vertices, normals):
    """Share of ``points`` behind the surface at their nearest vertex (inside the body)."""
    # A handful of points: a brute-force nearest vertex beats building a tree.
    d2 = (np.einsum("vd,vd->v", vertices, vertices)[None, :] - 2.0 * points @ vertices.T)
    near = d2.argmin(axis=1)
    return float(np.mean(np.einsum("ij,ij->i", points - vertices[near], normals[near]) < 0))


def infer_leaf_tails(skeleton, deform, vertices, nearest_owner, rays=None, tails=None):
    """Tails for deforming leaf joints that have none (see the module notes).

    Parameters
    ----------
    skeleton : Skeleton
    deform : (J,) bool
    vertices : (V, 3) float64
    nearest_owner : (V,) int
        For each vertex, the joint owning its nearest segment, leaves taken as points.
    rays : SurfaceRays, optional
        For clipping tails to the mesh.

    Returns
    -------
    tails : (J, 3) float64
        The skeleton's tails with inferred ones filled in (NaN elsewhere).
    """
    heads = skeleton.bind_matrices[:, :3, 3]
    tails = (skeleton.tails if tails is None else tails).copy()
    todo = [j for j in np.flatnonzero(deform)
            if not np.all(np.isfinite(tails[j])) and len(skeleton.children(j)) == 0]
    if not todo:
        return tails
    dirs, lengths = np.zeros((len(todo), 3)), np.zeros(len(todo))
    order = np.argsort(nearest_owner, kind="stable")
    bounds = np.searchsorted(nearest_owner[order], [todo, np.add(todo, 1)])
    for n, j in enumerate(todo):  # a loop over leaf joints, not vertices
        region = vertices[order[bounds[0, n]:bounds[1, n]]] - heads[j]
        p = skeleton.parents[j]
        parent_dir = heads[j] - heads[p] if p >= 0 else np.zeros(3)
        d = region.mean(axis=0) if len(region) >= MIN_REGION else np.zeros(3)
        spread = np.linalg.norm(region, axis=1).max() if len(region) else 0.0
        if np.linalg.norm(d) < 0.1 * spread or len(region) < MIN_REGION:
            d = parent_dir
        norm = np.linalg.norm(d)
        if norm < 1e-12:
            continue  # nothing to go on: the leaf stays a point
        d = d / norm
        if len(region) >= MIN_REGION:
            length = REACH * max(float((region @ d).max()), 0.0)
        else:
            length = 0.5 * np.linalg.norm(parent_dir)
        dirs[n], lengths[n] = d, length
    if rays is not None:
        idx = np.array(todo)
        far = heads[idx] + dirs * np.maximum(lengths, 1e-12)[:, None] / REACH
        t = rays.first_hit(heads[idx], far)
        lengths = lengths * np.where(np.isfinite(t), np.minimum(t, 1.0), 1.0)
    for n, j in enumerate(todo):
        if lengths[n] > 0:
            tails[j] = heads[j] + dirs[n] * lengths[n]
    return tails


def branch_tails(skeleton, deform, tails):
    """One tail for each deforming joint with several children and no tail of its own:
    toward the centroid of the children, as long as the nearest child is from the joint
    (Blender's glTF importer's bone, without its snap to the local axes). Without it such a
    joint owns a segment to each child.

    Parameters
    ----------
    skeleton : Skeleton
    deform : (J,) bool
    tails : (J, 3) float64
        NaN rows where a joint has no tail.

    Returns
    -------
    tails : (J, 3) float64
        A copy with those tails filled in.
    """
    heads = skeleton.bind_matrices[:, :3, 3]
    tails = tails.copy()
    for j in np.flatnonzero(deform):
        kids = skeleton.children(j)
        if len(kids) < 2 or np.all(np.isfinite(tails[j])):
            continue
        off = heads[kids] - heads[j]
        length = np.linalg.norm(off, axis=1)
        off, length = off[length > 1e-12], length[length > 1e-12]
        centre = off.mean(axis=0) if len(off) else np.zeros(3)
        if len(off) >= 2 and np.linalg.norm(centre) > 1e-12:
            tails[j] = heads[j] + centre / np.linalg.norm(centre) * length.min()
    return tails


def ik_chain_tails(skeleton, deform, tails, max_angle=60.0, reach=3.0):
    """Tails for leaf joints whose chain ends at a foot IK target: the target's head.

    Rigs made for IK (Quaternius' animals, RobotExpressive) end a leg chain at a leaf (the
    lower leg) and put the foot under the root as the IK target, at the hoof. The lower
    leg's bone runs down to that target, but a tail inferred from the mesh stops halfway:
    the target's own inferred tail, pointing up the shin, takes the lower half (the horse's
    shins went 0.69 to the foot target; the artist gave them 0.94 to the lower leg).

    A tail-less deforming leaf ``L`` whose parent is not a root takes as its tail the head of
    the nearest *target*: another leaf whose parent is a root, within ``reach`` times the
    length of ``L``'s parent bone and within ``max_angle`` degrees of that bone's direction.
    Each target serves one leaf (the nearest). Parameters and result as for
    :func:`branch_tails`.
    """
    heads = skeleton.bind_matrices[:, :3, 3]
    parents = skeleton.parents
    tails = tails.copy()
    leaf = np.array([len(skeleton.children(j)) == 0 for j in range(len(parents))])
    targets = [t for t in np.flatnonzero(leaf) if parents[t] >= 0 and parents[parents[t]] < 0]
    if not targets:
        return tails
    pairs = []
    for j in np.flatnonzero(deform & leaf & ~np.isfinite(tails[:, 0])):
        p = parents[j]
        if p < 0 or parents[p] < 0 or j in targets:
            continue
        bone = heads[j] - heads[p]
        length = np.linalg.norm(bone)
        if length < 1e-12:
            continue
        for t in targets:
            to = heads[t] - heads[j]
            d = np.linalg.norm(to)
            if 1e-12 < d <= reach * length and \
                    to @ bone >= np.cos(np.radians(max_angle)) * d * length:
                pairs.append((d, j, t))
    used_j, used_t = set(), set()
    for d, j, t in sorted(pairs):
        if j not in used_j and t not in used_t:
            tails[j] = heads[t]
            used_j.add(j)
            used_t.add(t)
    return tails
