"""Legs found by structure, for retargeting skeletons that are not humanoids (quadrupeds,
birds, anything with feet on the floor).

A *foot* is a leaf joint whose lowest point (the joint or its tail) lies within ``FOOT_TOL``
of the figure's height above the lowest leaf in a standing pose. Its *leg* is the
chain from that leaf up to the first ancestor that branches and stands at least
``BRANCH_HEIGHT`` of the height above the floor (so a bird's toes, which branch at the foot,
make one leg that starts at the thigh). In a leg the *knee* is the joint named so when
exactly one is, else the joint between the two longest consecutive segments (as for the
humanoid limbs); the joints from the knee's child down (the *foot part*) move rigidly with it
during the foot clean-up, and the bone above the knee and the knee's own bone are solved by
two-bone IK. The *hips* is the lowest common ancestor of the legs; the *chest* is where the
other legs (a quadruped's fore legs) branch. Body axes: up is +Y; forward is horizontal from
the hind feet to the fore feet when the legs hang from two places, else heel to toe.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .calibrate import ancestors, foot_points, tail_point
from ...model.transforms import unit
from .name_map import _KNEE, bend_index

__all__ = ["Leg", "find_legs", "ancestors", "LegCalibration", "leg_contacts", "ground",
           "motion_ground", "LEG_GROUPS", "FOOT_TOL", "BRANCH_HEIGHT"]

FOOT_TOL = 0.1
BRANCH_HEIGHT = 0.3
#: Groups of bones reported by :func:`rigedit.rigging.retarget.measure.direction_errors`.
LEG_GROUPS = ("legs", "spine", "head", "tail")


@dataclass
class Leg:
    """One leg: ``chain`` from the joint below its branch point down to the foot leaf;
    ``upper``, ``knee``, ``ankle`` the two-bone IK joints; ``foot`` the joints of the foot
    part (the ankle's subtree), which keep their model rotations; ``contact`` the foot leaf."""

    chain: list
    upper: int
    knee: int
    ankle: int
    contact: int
    foot: list


def tail_points(skeleton, mats):
    """(J, 3) model positions of the joints' tails in the pose ``mats`` (J, 4, 4); NaN where a
    joint has none."""
    out = np.full((len(skeleton), 3), np.nan)
    for j in np.flatnonzero(np.all(np.isfinite(skeleton.tails), axis=1)):
        out[j] = tail_point(skeleton, mats[None], j)[0]
    return out


def find_legs(skeleton, mats):
    """The legs of a skeleton standing in the pose ``mats``.

    Parameters
    ----------
    skeleton : Skeleton
    mats : (J, 4, 4) float64
        Model matrices of a standing pose (Y up).

    Returns
    -------
    legs : list of Leg
        In joint order of their foot leaves; empty when nothing stands on the floor.
    hips : int or None
        Lowest common ancestor of the legs.
    chest : int or None
        Branch point of the legs that do not hang from the hips (None when all do).
    """
    points = mats[:, :3, 3]
    tails = tail_points(skeleton, mats)
    low = np.fmin(points[:, 1], tails[:, 1])
    n_kids = np.bincount(skeleton.parents[skeleton.parents >= 0], minlength=len(skeleton))
    leaves = np.flatnonzero(n_kids == 0)
    # the lowest leaf, not the lowest joint: a ground-level root carrier is no foot
    floor = float(low[leaves].min())
    height = float(np.nanmax(np.r_[points[:, 1], tails[:, 1]]) - floor) or 1.0
    by_top = {}
    for leaf in leaves:
        if low[leaf] - floor > FOOT_TOL * height:
            continue
        chain, p = [int(leaf)], skeleton.parents[leaf]
        while p >= 0 and not (n_kids[p] >= 2 and points[p, 1] - floor >= BRANCH_HEIGHT * height):
            chain.insert(0, int(p))
            p = skeleton.parents[p]
        if p < 0 or points[chain[0], 1] - low[leaf] < 0.25 * height:
            continue  # no branch above it (a single chain), or too short to be a leg
        if chain[0] not in by_top or low[leaf] < low[by_top[chain[0]][-1]]:
            by_top[chain[0]] = chain
    legs = []
    for chain in sorted(by_top.values(), key=lambda c: c[-1]):
        k = bend_index(skeleton, chain, points, _KNEE)
        if k is None or k + 1 >= len(chain):
            continue  # fewer than three joints: nothing to bend
        legs.append(Leg(chain, chain[k - 1], chain[k], chain[k + 1], chain[-1],
                        [int(j) for j in skeleton.subtree(chain[k + 1])]))
    if not legs:
        return [], None, None
    tops = [ancestors(skeleton, skeleton.parents[leg.chain[0]]) for leg in legs]
    common = set(tops[0]).intersection(*tops[1:])
    hips = next(a for a in tops[0] if a in common)
    others = [t[0] for t in tops if t[0] != hips]
    chest = max(set(others), key=others.count) if others else None
    return legs, hips, chest


class LegCalibration:
    """A standing pose of any skeleton with legs: its legs, hips, body frame and floor.

    Offers what :class:`rigedit.rigging.retarget.calibrate.Calibration` offers the retargeting
    (``mats``, ``points``, ``source``, ``forward``, ``left``, ``up``, ``contacts``,
    ``floor``, ``joint_floor``, ``hip_height``, ``hip_offset``, ``hips``,
    ``foot_points``), with ``legs`` for the clean-up and ``group`` for the measures.

    Attributes
    ----------
    contacts : list of int
        The foot leaves, one per leg.
    hip_height : float
        Length of the legs hanging from the hips (a quadruped's hind legs), from their top
        joint to the foot leaf, plus the leaf's height above the floor: the height of their
        top joints were they standing straight.
    hip_offset : float
        Height of the hips joint above those legs' top joints in the pose.
    """

    kind = "legs"
    groups = LEG_GROUPS

    def __init__(self, skeleton, mats, source, what):
        self.skeleton, self.mats, self.source = skeleton, mats, source
        self.points = p = mats[:, :3, 3]
        self.legs, self.hips, self.chest = find_legs(skeleton, mats)
        if not self.legs:
            raise ValueError(f"{what}: expected legs (chains of three or more joints going "
                             f"down from the body to a foot on the floor, in the {source} "
                             f"pose), found none")
        self.contacts = [leg.contact for leg in self.legs]
        self.feet = sorted({j for leg in self.legs for j in leg.foot})
        self.floor = float(self.foot_points(mats[None])[0, :, 1].min())
        self.joint_floor = float(p[self.contacts, 1].min())
        if p[self.hips, 1] - self.joint_floor <= 1e-6 * max(float(np.ptp(p, axis=0).max()),
                                                            1e-9):
            raise ValueError(f"{what}: expected hips ({skeleton.names[self.hips]}) above the "
                             f"feet, got them at the feet's height")
        # Leg length standing straight, as for humanoids: the bones from the top of each
        # leg hanging from the hips down to the foot leaf, and the leaf's height, so that a
        # rest with bent legs does not shrink it; the hips joint sits hip_offset above the
        # legs' top joints.
        hind = [leg for leg in self.legs if self.hind(leg)] or self.legs
        self.hip_height = float(np.mean([self.straight(leg) for leg in hind]))
        self.hip_offset = float(p[self.hips, 1] - np.mean([p[leg.chain[0], 1] for leg in hind]))
        self.up = np.array([0.0, 1.0, 0.0])
        self.forward = self._forward()
        self.left = np.cross(self.up, self.forward)

    def foot_points(self, mats):
        """(F, P, 3) model positions of the foot-part joints (and their tails)."""
        return foot_points(self.skeleton, self.feet, mats)

    def _forward(self):
        p = self.points
        fore = [leg.contact for leg in self.legs if not self.hind(leg)]
        hind = [leg.contact for leg in self.legs if self.hind(leg)]
        fwd = np.zeros(3)
        if fore and hind:
            fwd = p[fore].mean(axis=0) - p[hind].mean(axis=0)
        fwd[1] = 0.0
        if np.linalg.norm(fwd) < 1e-6 * self.hip_height:
            for leg in self.legs:  # heel to toe: ankle to the foot's far end
                fwd += (self._end(leg) - p[leg.ankle]) * [1, 0, 1]
        if np.linalg.norm(fwd) < 1e-6 * self.hip_height:
            fwd = np.array([0.0, 0.0, 1.0])
        return unit(fwd)

    def hind(self, leg):
        """Whether ``leg`` hangs from the hips (a quadruped's hind legs, a biped's two)."""
        return self.skeleton.parents[leg.chain[0]] == self.hips

    def straight(self, leg):
        """The leg's length standing straight, whatever the pose: its bones' lengths from the
        top joint down to the foot leaf, and the leaf's tail (a hoof) where it has one."""
        p = self.points
        end = float(np.linalg.norm(self._end(leg) - p[leg.contact]))
        return float(np.linalg.norm(np.diff(p[leg.chain], axis=0), axis=1).sum() + end)

    def _end(self, leg):
        """(3,) the foot leaf's tail in the pose, or the leaf itself when it has none."""
        tail = tail_point(self.skeleton, self.mats[None], leg.contact)
        return self.points[leg.contact] if tail is None else tail[0]

    def leg_counts(self):
        """(legs hanging from the hips, legs hanging from elsewhere)."""
        hind = sum(self.hind(leg) for leg in self.legs)
        return hind, len(self.legs) - hind

    def group(self, j):
        """The measure group of joint ``j``: ``legs``, ``spine`` (hips to chest), ``head``
        (the chest's other joints: neck, head), ``tail`` (the hips' other joints), or None
        for joints above the hips."""
        sk = self.skeleton
        if any(j in leg.chain for leg in self.legs):
            return "legs"
        up = ancestors(sk, j)
        if self.hips not in up:
            return None
        if self.chest is None:
            return "spine"
        between = ancestors(sk, self.chest)
        if j in between:
            return "spine"
        return "head" if self.chest in up else "tail"


def leg_contacts(src, tgt, inverse, contact):
    """Each target leg's contact mask, from the source leg its lowest mapped joint lies in.

    Returns
    -------
    contact : (F, len(tgt.legs)) bool
        All False for a leg no source leg maps onto (it is still kept above the floor).
    source_points : list of int
        The source foot leaf per target leg (the first source leaf for an unmatched leg,
        which never touches in ``contact``).
    source_legs : list of int or None
        The index of the source leg per target leg.
    """
    out = np.zeros((len(contact), len(tgt.legs)), dtype=bool)
    points = [src.contacts[0]] * len(tgt.legs)
    legs = [None] * len(tgt.legs)
    for i, leg in enumerate(tgt.legs):
        mapped = [inverse[j] for j in reversed(leg.chain) if j in inverse]
        for k, s_leg in enumerate(src.legs):
            if mapped and mapped[0] in s_leg.chain:
                out[:, i], points[i], legs[i] = contact[:, k], s_leg.contact, k
                break
    return out, points, legs


def ground(src, tgt, smats, raw, s_legs, scale):
    """Where the target's feet stand: the vertical shift that puts its lowest foot point on
    its floor as often as the source's stands on the source's ground (both: the 5th
    percentile over the frames of the lowest foot point, so that a rest with other foot
    angles does not sink or lift the motion), and the height of each target foot leaf during
    contacts, before the shift: its foot's lowest point as high above the floor as the
    source foot's, scaled, the leaf above that point as the foot's turn puts it.

    Returns
    -------
    shift : float
    heights : (F, len(tgt.legs)) float64
    """
    s_ground = motion_ground(src, smats)
    shift = tgt.floor - motion_ground(tgt, raw)
    heights = raw[:, tgt.contacts, 1, 3].copy()
    for i, (leg, k) in enumerate(zip(tgt.legs, s_legs)):
        if k is None:
            continue
        t_low = foot_points(tgt.skeleton, leg.foot, raw)[..., 1].min(axis=1)
        s_low = foot_points(src.skeleton, src.legs[k].foot, smats)[..., 1].min(axis=1)
        heights[:, i] += tgt.floor - shift + scale * (s_low - s_ground) - t_low
    return shift, heights


def motion_ground(cal, mats):
    """The ground a motion stands on: the 5th percentile over the frames of the lowest foot
    point of the legs hanging from the hips (which place the hips; a quadruped's fore legs
    are fitted by :func:`rigedit.rigging.retarget.pitch.pitch_body`), in the poses ``mats``
    (F, J, 4, 4)."""
    feet = [j for leg in cal.legs if cal.hind(leg) for j in leg.foot] or cal.feet
    return float(np.percentile(foot_points(cal.skeleton, feet, mats)[..., 1].min(axis=1), 5))
