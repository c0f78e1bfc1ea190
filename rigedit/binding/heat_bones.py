"""The bones heat flows from: the deforming joints, their segments (tails inferred for
leaves), and each welded vertex's distance to each joint's nearest segment
(:mod:`.heat`)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .distance import point_segment_distance
from .tails import branch_tails, deforming_joints, ik_chain_tails, infer_leaf_tails

__all__ = ["Bones", "heat_bones", "joint_distances", "nearest_on_segment", "CHUNK"]

CHUNK = 16384           # vertices per block of the distance computation


@dataclass
class Bones:
    """The deforming bones and each vertex's distance to them.

    Attributes
    ----------
    deform : (J,) bool
        The joints that can take weight.
    tails : (J, 3) float64
        The bone tails used (inferred for leaves), NaN for joints with none.
    starts, ends : (S, 3) float64
        The bones' segments, grouped by owner.
    owners : (S,) int
        The joint owning each segment.
    joints : (J',) int
        The joints owning a segment, sorted (the columns below).
    dist : (W, J') float64
        Each vertex's distance to each joint's nearest segment.
    seg : (W, J') int32
        That segment.
    """

    deform: np.ndarray
    tails: np.ndarray
    starts: np.ndarray
    ends: np.ndarray
    owners: np.ndarray
    joints: np.ndarray
    dist: np.ndarray
    seg: np.ndarray


def heat_bones(skeleton, wv, normals, rays, helpers=True, ik_chains=True,
               branches="children", infer_tails=True):
    """The bones of ``skeleton`` heat flows from, measured from the welded vertices.

    Parameters
    ----------
    skeleton : Skeleton
    wv : (W, 3) float64
        The welded vertices.
    normals : (W, 3) float64
    rays : SurfaceRays
        For the leaves' inferred tails.
    helpers, ik_chains, branches, infer_tails
        As :func:`rigedit.binding.heat.heat_weights` takes them.

    Returns
    -------
    Bones
    """
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
    dist, seg = joint_distances(wv, starts, ends, owners, joints)
    if infer_tails:
        given = tails
        tails = infer_leaf_tails(skeleton, deform, wv,
                                 joints[dist.argmin(axis=1)], rays, tails=given)
        starts, ends, owners = skeleton.bone_segments(deform=deform, tails=tails)
        changed = np.isin(owners, np.flatnonzero(np.isfinite(tails[:, 0])
                                                 & ~np.isfinite(given[:, 0])))
        if changed.any():  # only the leaves that got a tail
            base = np.flatnonzero(changed)
            joint_distances(wv, starts[base], ends[base], owners[base], joints, dist, seg,
                            seg_index=base)
    return Bones(deform, tails, starts, ends, owners, joints, dist, seg)


def joint_distances(points, starts, ends, owners, joints, dist=None, seg=None,
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


def nearest_on_segment(points, starts, ends):
    """(N, 3) the nearest point to each of ``points`` (N, 3) on its segment ``starts`` ->
    ``ends`` (N, 3 each)."""
    seg = ends - starts
    l2 = np.einsum("ij,ij->i", seg, seg)
    t = np.einsum("ij,ij->i", points - starts, seg) / np.where(l2 > 0, l2, 1.0)
    return starts + np.clip(t, 0.0, 1.0)[:, None] * seg
