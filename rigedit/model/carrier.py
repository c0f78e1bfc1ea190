"""Carrier roots: joints above the figure that only carry it, found from structure and motion.

Mocap and game skeletons often put a joint above the hips that is not part of the body:
Bandai's ``joint_Root`` (at the origin while the figure walks 10 m, or travelling on the
floor under the hips), iClone's ``RL_BoneRoot`` (on the floor, turning a Z-up figure Y up),
a trajectory or "reference" joint. Its "bone" to the hips is no limb: it runs from the floor
up to the pelvis, or across the room. Counted as part of the figure it breaks every decision
that measures the figure: its size (the BVH unit guess), its slots (a 5 m "figure" has no
legs a quarter of its size long), its facing and the camera's framing.

A joint is a **carrier** when, walking down from a root through joints with exactly one
child, it carries the figure below it (the subtree of its child) in at least half the poses
looked at, where it carries it in a pose if either

- it stands at the figure's floor (within 5% of the figure's height of its lowest joint)
  while its child stands at least a quarter of that height above it (a carrier under the
  hips), or
- it lies outside the figure's bounding box grown by a quarter of the figure's size on each
  side (a carrier left at the origin while the figure walks away).

A root with several children (a body's hips) is never one, nor a joint above a figure that
does not branch (a plain chain of joints is a figure of its own), and the walk stops at the
first joint that is not a carrier. Names are not used: the same test holds for any naming.
Pure numpy; rigedit's frame is Y up (pass ``up`` otherwise).
"""
from __future__ import annotations

import numpy as np

from .skeleton import subtree_of

__all__ = ["carrier_joints", "carrier_note", "figure_root", "FLOOR", "CLIMB", "MARGIN",
           "MAX_CHAIN"]

#: A carrier "at the floor": within this fraction of the figure's height of its lowest joint.
FLOOR = 0.05
#: ... while its child (the figure's root) stands at least this fraction of it higher.
CLIMB = 0.25
#: A carrier "away from the figure": outside its bounding box grown by this fraction of
#: the figure's largest extent on each side.
MARGIN = 0.25
#: At most this many carriers in a row above a figure (iClone has two at most).
MAX_CHAIN = 3


def _children(parents):
    kids = [[] for _ in parents]
    for j, p in enumerate(parents):
        if p >= 0:
            kids[p].append(j)
    return kids


def _carries(points, c, child, figure, up):
    """(P,) bool: whether joint ``c`` carries the ``figure`` joints in each pose of
    ``points`` (P, J, 3); see the module notes."""
    fig = points[:, figure]
    lo, hi = fig.min(axis=1), fig.max(axis=1)
    size = np.max(hi - lo, axis=1)
    heights = fig @ up
    height = np.ptp(heights, axis=1)
    ch, kh = points[:, c] @ up, points[:, child] @ up
    at_floor = (ch <= heights.min(axis=1) + FLOOR * height) & (kh - ch >= CLIMB * height)
    grow = (MARGIN * size)[:, None]
    away = np.any((points[:, c] < lo - grow) | (points[:, c] > hi + grow), axis=1)
    return (at_floor | away) & (size > 0)


def carrier_joints(parents, points, up=(0.0, 1.0, 0.0)):
    """Which joints are carrier roots (see the module notes).

    Parameters
    ----------
    parents : (J,) int
        Parent of each joint, -1 for a root (parents before children).
    points : (J, 3) or (P, J, 3) float
        Model-space joint positions in one pose or in P poses (say, frames sampled over a
        clip; the rest pose when there is no motion).
    up : (3,) float
        The vertical axis.

    Returns
    -------
    carriers : (J,) bool
    """
    parents = np.asarray(parents, dtype=np.int64)
    points = np.asarray(points, dtype=np.float64)
    if points.ndim == 2:
        points = points[None]
    up = np.asarray(up, dtype=np.float64)
    up = up / np.linalg.norm(up)
    kids = _children(parents)
    out = np.zeros(len(parents), dtype=bool)
    finite = np.all(np.isfinite(points), axis=(1, 2))
    points = points[finite]
    if not len(points):
        return out
    for r in np.flatnonzero(parents < 0):
        c = int(r)
        for _ in range(MAX_CHAIN):
            if len(kids[c]) != 1:
                break
            child = kids[c][0]
            figure = subtree_of(parents, child)
            if not any(len(kids[k]) >= 2 for k in figure) or \
                    np.mean(_carries(points, c, child, figure, up)) < 0.5:
                break
            out[c] = True
            c = child
    return out


def figure_root(parents, carriers):
    """The first joint below the carriers (the figure's root: the hips), else joint 0.

    Parameters
    ----------
    parents : (J,) int
    carriers : (J,) bool
        As :func:`carrier_joints` returns.
    """
    parents = np.asarray(parents)
    for j, p in enumerate(parents):
        if not carriers[j] and (p < 0 or carriers[p]):
            return j
    return 0


def carrier_note(names, parents, points, carriers, scale=1.0, unit="m"):
    """One line naming each carrier and how far it stood from the figure's root, or "".

    Parameters
    ----------
    names : sequence of str
    parents : (J,) int
    points : (P, J, 3) float
        The poses :func:`carrier_joints` looked at.
    carriers : (J,) bool
    scale : float
        Length unit of ``points`` in ``unit``\\ s (a BVH file's metres per unit).
    """
    points = np.asarray(points, dtype=np.float64)
    if points.ndim == 2:
        points = points[None]
    root = figure_root(parents, carriers)
    parts = []
    for c in np.flatnonzero(carriers):
        gap = np.linalg.norm(points[:, c] - points[:, root], axis=-1) * scale
        parts.append(f"{names[c]} ({gap.min():.2g}-{gap.max():.2g} {unit} from "
                     f"{names[root]})" if np.ptp(gap) > 0.05 * max(gap.max(), 1e-12)
                     else f"{names[c]} ({gap.max():.2g} {unit} from {names[root]})")
    if not parts:
        return ""
    return ("carrier root " + ", ".join(parts) + ": it only carries the figure, left out of "
            "its size, units, facing and framing")
