"""Humanoid slots found from the tree's shape: hips, spine, chest, neck, head and the limbs.

A humanoid's joints are sorted into *slots*: ``hips``, the spine interior, ``chest`` (where the
arms branch), ``neck``, ``head`` and per side ``clavicle``, ``upper_arm``, ``forearm``,
``hand``, ``thigh``, ``shin``, ``foot``, ``toe`` (suffix ``_L`` / ``_R``). Names alone cannot
do it: CMU's ``LeftShoulder`` is an upper arm where Mixamo's is a clavicle, and CesiumMan
numbers its arm joints 4, 3, 2. So the limbs are found by structure, in a pose where the figure
stands (the calibration pose): the hips are the first joint with two chains going down and one
going up, the chest the first joint up the spine with two side chains; in a limb chain the
knee (elbow) is the joint named so when exactly one is, otherwise the joint between the two
longest consecutive segments. Sides come from the names (:mod:`.joint_names`) when both
chains carry one, otherwise from the side of the figure's left (``up x forward``, forward
from heel to toe). The legs may hang from a pelvis joint below the hips (iClone), limb chains
pass over twist and share bones beside the real child, and sizes leave out the joints above
the first branch (a carrier root may stand metres away).
"""
from __future__ import annotations

import numpy as np

from .joint_names import ELBOW, KNEE, normalise_name

__all__ = ["find_slots", "bend_index", "LIMB_SLOTS"]

LIMB_SLOTS = ("clavicle", "upper_arm", "forearm", "hand", "thigh", "shin", "foot", "toe")


def find_slots(skeleton, points, what="skeleton"):
    """Sort a humanoid skeleton's joints into slots.

    Parameters
    ----------
    skeleton : Skeleton
    points : (J, 3) float64
        Model-space joint positions in a standing pose (Y up).
    what : str
        How to name the skeleton in errors (a file name).

    Returns
    -------
    slots : dict[str, int]
        Slot name -> joint index (``hips``, ``chest``, ``neck``, ``head``, ``thigh_L``...).
    chains : dict[str, list[int]]
        ``spine``: hips to chest inclusive; ``neck``: chest's child up to the head.
    forward : (3,) float64
        The figure's horizontal forward direction (heel to toe), unit length.

    Raises
    ------
    ValueError
        When no hips with two legs below and a spine above, or no arms, are found.
    """
    points = np.asarray(points, dtype=np.float64)
    # the figure's size, without the joints above its first branch: a carrier root (Bandai's
    # joint_Root, iClone's RL_BoneRoot) may stand metres from the figure
    size = float(np.ptp(points[_figure_joints(skeleton)], axis=0).max()) or 1.0
    tree = _subtree_measures(skeleton, points)
    lo, hi, count, reach = tree
    hips, legs, spine_start = _find_hips(skeleton, points, tree, size, what)
    # down the child with the most joints below it (the foot and toes, not a twist or share
    # helper bone beside them), the lowest on a tie
    leg_chains = [_chain(skeleton, c, count * 4 * size - lo) for c in legs]
    slots = {"hips": hips}
    spine = [hips] + _chain(skeleton, spine_start, hi)
    chest, arms, cut = _find_chest(skeleton, spine, count, reach, size, what)
    _check_upright(skeleton, points, hips, chest, what)
    slots["chest"] = chest
    chains = {"spine": spine[:cut + 1], "neck": spine[cut + 1:]}
    _neck_and_head(skeleton, chains, slots)
    limbs, fwd = _leg_parts(skeleton, points, leg_chains, what)
    limbs.update(_arm_parts(skeleton, points, arms, reach, what))
    if np.linalg.norm(fwd) < 1e-6 * size:
        fwd = np.array([0.0, 0.0, 1.0])
    fwd /= np.linalg.norm(fwd)
    _name_sides(skeleton, points, hips, (legs, arms), limbs, fwd, slots)
    return slots, chains, fwd


def _subtree_measures(skeleton, points):
    """Per joint, over its subtree: the lowest and highest y, the number of joints, and the
    furthest distance from the joint (``lo, hi, count, reach``, each (J,) float64).

    points : (J, 3) joint positions; leaf tails are folded in by the caller via ``points``."""
    n = len(skeleton)
    lo, hi = points[:, 1].copy(), points[:, 1].copy()
    for j in range(n - 1, 0, -1):
        p = skeleton.parents[j]
        if p >= 0:
            lo[p], hi[p] = min(lo[p], lo[j]), max(hi[p], hi[j])
    count = np.ones(n)
    reach = np.zeros(n)
    for j in range(n - 1, 0, -1):
        p = skeleton.parents[j]
        if p >= 0:
            count[p] += count[j]
    for j in range(n):
        a = j
        while a >= 0:
            reach[a] = max(reach[a], np.linalg.norm(points[j] - points[a]))
            a = skeleton.parents[a]
    return lo, hi, count, reach


def _figure_joints(skeleton):
    """Joints from the first branching joint (or the last joint of a chain) down: the ones
    above it only carry the figure."""
    j = int(np.flatnonzero(skeleton.parents < 0)[0])
    while len(skeleton.children(j)) == 1:
        j = int(skeleton.children(j)[0])
    return skeleton.subtree(j)


def _chain(skeleton, start, score):
    """Follow the child with the highest ``score`` from ``start`` down to a leaf."""
    chain = [start]
    while True:
        kids = skeleton.children(chain[-1])
        if len(kids) == 0:
            return chain
        chain.append(int(kids[np.argmax(score[kids])]))


def bend_index(skeleton, chain, points, keywords):
    """Index in ``chain`` of the knee or elbow: the one joint named so, else the joint between
    the two longest consecutive segments (it needs a joint on each side)."""
    named = [i for i, j in enumerate(chain) if normalise_name(skeleton.names[j])[1] in keywords]
    if len(named) == 1 and 1 <= named[0] <= len(chain) - 2:
        return named[0]
    if len(chain) < 3:
        return None
    seg = np.linalg.norm(np.diff(points[chain], axis=0), axis=1)
    return int(np.argmax(seg[:-1] + seg[1:])) + 1


def _find_hips(skeleton, points, tree, size, what):
    """``(hips, legs, spine_start)``: the first joint with two chains going down (the legs'
    first joints, lowest first) and one going up (the spine's first joint)."""
    lo, hi, count, _ = tree

    def going_down(j):
        return [c for c in skeleton.children(j)
                if lo[c] < points[j, 1] - 0.25 * size and count[c] >= 2]

    for j in range(len(skeleton)):
        kids = skeleton.children(j)
        down = going_down(j)
        up = [c for c in kids if hi[c] > points[j, 1] + 0.15 * size]
        if len(down) < 2 and up:
            # the legs may hang from a pelvis joint below the hips (iClone's CC_Base_Pelvis:
            # the hips' child with the two legs and nothing going up)
            for c in down:
                if len(going_down(c)) >= 2 and not any(hi[k] > points[j, 1] + 0.15 * size
                                                        for k in skeleton.children(c)):
                    down = going_down(c)
                    break
        if len(down) >= 2 and up:
            return j, sorted(down, key=lambda c: lo[c])[:2], max(up, key=lambda c: hi[c])
    raise ValueError(f"{what}: expected a humanoid with two legs (two joint chains going "
                     f"down from the hips) and a spine, found no such joint")


def _find_chest(skeleton, spine, count, reach, size, what):
    """``(chest, arms, cut)``: the first joint up the ``spine`` chain with two side chains
    (the arms' first joints, longest reach first), and its index in ``spine``."""
    for i, j in enumerate(spine[1:], 1):
        kids = [c for c in skeleton.children(j) if c != (spine[i + 1] if i + 1 < len(spine)
                                                          else -1)]
        side = [c for c in kids if count[c] >= 3 and reach[c] > 0.12 * size]
        if len(side) >= 2:
            return j, sorted(side, key=lambda c: -reach[c])[:2], i
    raise ValueError(f"{what}: expected two arms branching from the spine, found none")


def _check_upright(skeleton, points, hips, chest, what):
    """Raise unless the spine from the hips to the chest is within 45 degrees of vertical."""
    rise = points[chest] - points[hips]
    if rise[1] < 0.7 * np.linalg.norm(rise):  # more than 45 degrees from vertical
        raise ValueError(f"{what}: expected an upright spine from the hips "
                         f"({skeleton.names[hips]}) to the chest ({skeleton.names[chest]}), "
                         f"got one {np.degrees(np.arccos(rise[1] / np.linalg.norm(rise))):.0f} "
                         f"degrees from vertical (not a standing humanoid)")


def _neck_and_head(skeleton, chains, slots):
    """The head (the one neck joint named so, else the chain's end) and the neck's first
    joint into ``slots``; ``chains["neck"]`` cut at the head. Both changed in place."""
    neck = chains["neck"]
    if neck:
        heads = [j for j in neck if normalise_name(skeleton.names[j])[1] == "head"]
        head = heads[0] if len(heads) == 1 else neck[-1]
        chains["neck"] = neck[:neck.index(head) + 1]
        slots["head"] = head
        if len(chains["neck"]) >= 2:
            slots["neck"] = chains["neck"][0]


def _leg_parts(skeleton, points, leg_chains, what):
    """``({first joint: {slot: joint}}, forward)``: each leg's thigh, shin, foot and toe,
    and the horizontal sum of the ankle-to-toe (or foot's end) directions (3,)."""
    limbs = {}
    fwd = np.zeros(3)
    for ch in leg_chains:
        k = bend_index(skeleton, ch, points, KNEE)
        if k is None or k + 1 >= len(ch):
            raise ValueError(f"{what}: expected a leg of hip, knee and ankle, got the chain "
                             f"{[skeleton.names[j] for j in ch]}")
        part = {"thigh": ch[k - 1], "shin": ch[k], "foot": ch[k + 1]}
        if k + 2 < len(ch):
            part["toe"] = ch[k + 2]
        end = points[ch[-1]] if ch[-1] != ch[k + 1] else points[ch[k + 1]]
        fwd += (end - points[ch[k + 1]]) * [1, 0, 1]
        limbs[ch[0]] = part
    return limbs, fwd


def _arm_parts(skeleton, points, arms, reach, what):
    """``{first joint: {slot: joint}}``: each arm's clavicle, upper arm, forearm and hand."""
    limbs = {}
    for c in arms:
        ch = _chain(skeleton, c, reach)
        k = bend_index(skeleton, ch, points, ELBOW)
        if k is None:
            raise ValueError(f"{what}: expected an arm of shoulder, elbow and wrist, got the "
                             f"chain {[skeleton.names[j] for j in ch]}")
        part = {"upper_arm": ch[k - 1], "forearm": ch[k], "hand": ch[k + 1]}
        if k >= 2:
            part["clavicle"] = ch[k - 2]
        limbs[c] = part
    return limbs


def _name_sides(skeleton, points, hips, pairs, limbs, fwd, slots):
    """Each limb's slots into ``slots`` with its side: from the names when the pair's limbs
    name one side each, else from the figure's left (``up x fwd``)."""
    left = np.cross([0.0, 1.0, 0.0], fwd)
    for pair in pairs:
        named = [_side_of(skeleton, limbs[c]) for c in pair]
        if sorted(s for s in named if s) != ["L", "R"]:
            x = [float(np.dot(points[c] - points[hips], left)) for c in pair]
            named = ["L", "R"] if x[0] > x[1] else ["R", "L"]
        for c, s in zip(pair, named):
            for slot, j in limbs[c].items():
                slots[f"{slot}_{s}"] = j


def _side_of(skeleton, part):
    """The side the names of a limb's joints agree on, or None."""
    sides = {normalise_name(skeleton.names[j])[0] for j in part.values()} - {None}
    return sides.pop() if len(sides) == 1 else None
