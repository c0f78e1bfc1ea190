"""The error budget: how far each track may stray, tighter towards the root.

A joint's error moves every virtual vertex below it, so its tolerance in its own units is the
bound divided by how far its error reaches:

- a rotation error of ``|dq|`` (quaternion distance) moves a point ``R`` metres away by at most
  ``2 R |dq|``, ``R`` = :func:`reach` (the farthest virtual vertex of the joint's subtree at
  bind): the hips, reaching the hands and feet, get a far smaller tolerance than a finger tip;
- a translation error moves its subtree by itself times the parent's scale;
- a scale error of ``ds`` moves a point ``R`` away by ``R ds / s``.

Errors along a chain add up, so each joint's share of the bound is ``max_error * factor``,
``factor = 1 / sqrt(n)`` to start with (``n``: joints on the longest root-to-leaf path through
the joint); the pipeline halves the factor of the joints on the path of any joint the check
finds over the bound, and redoes them; once the clip holds, joints whose subtree stayed well
under the bound get a larger share (:meth:`Budget.relax`) and the clip is encoded again, the
smallest encoding that holds kept.
"""
from __future__ import annotations

import numpy as np

__all__ = ["reach", "path_lengths", "model_scale", "with_ancestors", "Budget"]


def model_scale(skeleton):
    """Each joint's mean model scale at bind, (J,)."""
    s = np.linalg.norm(skeleton.bind_matrices[:, :3, :3], axis=1).mean(axis=1)
    return np.where(s > 1e-12, s, 1.0)


def reach(skeleton, distances):
    """Model-space distance (J,) from each joint at bind to the farthest virtual vertex of its
    subtree (its own at ``distances[j]``, a child's through the child)."""
    heads = skeleton.bind_matrices[:, :3, 3]
    out = np.asarray(distances, dtype=np.float64).copy()
    for j in range(len(skeleton) - 1, 0, -1):      # children are stored after parents
        p = skeleton.parents[j]
        if p >= 0:
            out[p] = max(out[p], out[j] + float(np.linalg.norm(heads[j] - heads[p])))
    return out


def path_lengths(skeleton):
    """Joints on the longest root-to-leaf path through each joint, (J,) int."""
    below = np.zeros(len(skeleton), dtype=np.int64)
    for j in range(len(skeleton) - 1, 0, -1):
        p = skeleton.parents[j]
        if p >= 0:
            below[p] = max(below[p], below[j] + 1)
    return skeleton.depth + 1 + below


def with_ancestors(skeleton, joints):
    """(J,) bool: ``joints`` and every joint on their paths to the root."""
    hit = np.zeros(len(skeleton), dtype=bool)
    for j in np.atleast_1d(joints):
        j = int(j)
        while j >= 0 and not hit[j]:
            hit[j] = True
            j = int(skeleton.parents[j])
    return hit


class Budget:
    """Per-joint tolerances of one skeleton at one bound.

    Parameters
    ----------
    skeleton : Skeleton
    max_error : float
        Metres.
    distances : (J,) float
        Model-space shell distances (:func:`~rigedit.compression.virtual.shell_distances`).
    """

    def __init__(self, skeleton, max_error, distances):
        self.skeleton = skeleton
        self.max_error = float(max_error)
        self.reach = reach(skeleton, distances)
        self.factor = 1.0 / np.sqrt(path_lengths(skeleton))
        scale = model_scale(skeleton)
        parents = skeleton.parents
        self.parent_scale = np.where(parents >= 0, scale[np.maximum(parents, 0)], 1.0)
        self.rest_scale = np.abs(skeleton.rest_scale).mean(axis=1)

    def metres(self, joint):
        """The joint's share of the bound, metres."""
        return self.max_error * self.factor[joint]

    def tolerance(self, joint, channel):
        """The joint's tolerance in the channel's own units (quaternion distance for a
        rotation)."""
        share = self.metres(joint)
        if channel == "translation":
            return share / self.parent_scale[joint]
        if channel == "rotation":
            return share / (2.0 * self.reach[joint])
        return share * max(self.rest_scale[joint], 1e-12) / self.reach[joint]

    def relax(self, joint_error, power=0.7, most=2.0):
        """Give joints whose whole subtree stayed under the bound a larger share.

        ``joint_error``: (J,) the largest error each joint saw; a joint's share grows by
        ``(max_error / worst in its subtree) ** power``, at most ``most`` times.
        """
        worst = np.asarray(joint_error, dtype=np.float64).copy()
        for j in range(len(self.skeleton) - 1, 0, -1):
            p = self.skeleton.parents[j]
            if p >= 0:
                worst[p] = max(worst[p], worst[j])
        gain = (self.max_error / np.maximum(worst, 1e-300)) ** power
        self.factor *= np.clip(gain, 1.0, most)

    def tighten(self, joints, by=0.5):
        """Scale the share of ``joints`` and all their ancestors by ``by``."""
        hit = with_ancestors(self.skeleton, joints)
        self.factor[hit] *= by
        return hit
