"""Helper joints told from names and structure (rigedit.model.helper_joints)."""
from __future__ import annotations

import numpy as np

from rigedit.model.helper_joints import (CARRIER, END, SHARE, TARGET, TWIST, carrier_candidates,
                                         helper_joints)


def flags(names, parents, heads):
    r = helper_joints(names, parents, np.asarray(heads, float))
    return {n: x for n, x in zip(names, r) if x}


def test_end_markers_targets_twist_and_share_leaves_are_flagged():
    names = ["mixamorig:Hips", "mixamorig:Spine", "mixamorig:HeadTop_End",
             "mixamorig:LeftHandIndex3", "mixamorig:LeftHandIndex4", "PoleTarget.L",
             "CC_Base_L_UpperarmTwist01", "CC_Base_L_RibsShareBone", "Legend", "Bip01 R Finger0Nub"]
    parents = [-1, 0, 1, 1, 3, 0, 1, 1, 1, 1]
    heads = [[0, 1, 0], [0, 1.2, 0], [0, 1.8, 0], [0.5, 1.4, 0], [0.55, 1.4, 0],
             [0.1, 0.5, 0.5], [0.2, 1.4, 0], [0.1, 1.3, 0], [0, 1.5, 0], [-0.5, 1.4, 0]]
    got = flags(names, parents, heads)
    got.pop("mixamorig:Hips", None)  # a carrier candidate or not: the mesh decides
    assert got == {"mixamorig:HeadTop_End": END, "mixamorig:LeftHandIndex4": END,
                   "PoleTarget.L": TARGET, "CC_Base_L_UpperarmTwist01": TWIST,
                   "CC_Base_L_RibsShareBone": SHARE, "Bip01 R Finger0Nub": END}


def test_a_twist_joint_that_carries_a_chain_is_not_flagged():
    # UpperarmTwist -> Forearm: the twist joint's bone carries the arm below it
    got = flags(["Hips", "UpperarmTwist", "Forearm", "Hand"], [-1, 0, 1, 2],
                [[0, 1, 0], [0.2, 1.4, 0], [0.4, 1.4, 0], [0.6, 1.4, 0]])
    assert got == {"Hips": CARRIER}  # a chain's root is at its edge: only a candidate


def test_carrier_candidates_are_roots_at_the_origin_at_the_edge_or_named_so():
    chain = [[0, 1.0, 0], [0, 1.5, 0], [0.3, 0.1, 0.5]]
    # a hip root in the middle of the figure is no candidate
    assert len(carrier_candidates(["Hips", "Spine", "Foot.L", "Foot.R"], [-1, 0, 0, 0],
                                  [[0, 0.9, 0.2], [0, 1.5, 0.1], [0.3, 0.1, 0.5],
                                   [-0.3, 0.1, -0.1]])) == 0
    # a root on the ground under the figure (named like a bone) is
    assert list(carrier_candidates(["Bone", "Hips", "Spine"], [-1, 0, 1],
                                   [[0, 0.0, 0.1]] + chain[:2])) == [0]
    # named like a carrier, wherever it is
    assert list(carrier_candidates(["joint_Root", "Hips", "Spine", "Foot"], [-1, 0, 1, 1],
                                   [[0, 0.9, 0.2]] + chain)) == [0]
    assert flags(["root", "Hips"], [-1, 0], [[0, 0, 0], [0, 1, 0]]) == {"root": CARRIER}
