"""Pitching a four-legged body so that its fore and hind legs both reach, when their
proportions differ from the source's (fore legs shorter or longer than the hind legs, for
their length, than the source's).

Bone directions copied from the source place the fore legs' top joints (the shoulder
blades) where the source's spine puts them; with fore legs relatively shorter, the fore hooves
cannot reach the floor unless the whole body drops and the hind legs bend. Instead the
hips, spine, neck and head turn together about the hips joint, about the body's left axis,
frame by frame, so that the fore tops stand above the hind tops by what the source's do,
each pair's height above the ground scaled by its own legs' length ratio (straight length,
so any rest pose gives the same). The legs keep their directions (the foot clean-up then
solves them); the hind legs and the tail move only with the hips' position. With equal
ratios (any uniform scale) the turn is zero.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ...model.transforms import unit
from .limbs import motion_ground

__all__ = ["pitch_body"]


def pitch_body(src, tgt, rot, raw, smats, s_legs):
    """Turn the target's hips, spine, neck and head so its fore legs' tops stand where the
    source's, scaled by the fore legs' ratio, stand relative to the hind legs' tops.

    Parameters
    ----------
    src, tgt : LegCalibration
    rot : (F, Jt, 3, 3) float64
        Target model rotations (changed in place).
    raw : (F, Jt, 4, 4) float64
        Target model matrices assembled from ``rot``.
    smats : (F, Js, 4, 4) float64
        Source model matrices.
    s_legs : list of int or None
        The source leg of each target leg (:func:`rigedit.rigging.retarget.limbs.leg_contacts`).

    Returns
    -------
    theta : (F,) float64 or None
        The turn in radians per frame (positive lifts the front), None when the figure has
        no fore and hind legs mapped onto the source's.
    """
    sk = tgt.skeleton
    pairs = [(leg, src.legs[k]) for leg, k in zip(tgt.legs, s_legs) if k is not None]
    fore = [(t, s) for t, s in pairs if not tgt.hind(t) and not src.hind(s)]
    hind = [(t, s) for t, s in pairs if tgt.hind(t) and src.hind(s)]
    if tgt.chest is None or not fore or not hind:
        return None

    def ratio(legs):
        return np.mean([tgt.straight(t) for t, _ in legs]) / \
            np.mean([src.straight(s) for _, s in legs])

    def tops(mats, legs, k):
        return mats[:, [pair[k].chain[0] for pair in legs]][..., :3, 3].mean(axis=1)

    ground = motion_ground(src, smats)
    want = ratio(fore) * (tops(smats, fore, 1)[:, 1] - ground) \
        - ratio(hind) * (tops(smats, hind, 1)[:, 1] - ground)
    delta = want - (tops(raw, fore, 0)[:, 1] - tops(raw, hind, 0)[:, 1])
    pivot = tgt.chest
    while sk.parents[pivot] != tgt.hips:
        pivot = sk.parents[pivot]
    v = tops(raw, fore, 0) - raw[:, tgt.hips, :3, 3]
    h, y = np.linalg.norm(v[:, [0, 2]], axis=1), v[:, 1]
    reach = np.hypot(h, y)
    theta = np.arcsin(np.clip((y + delta) / reach, -1.0, 1.0)) - np.arctan2(y, h)
    axis = unit(np.cross(v * [1.0, 0.0, 1.0], [0.0, 1.0, 0.0]))
    turn = Rotation.from_rotvec(axis * theta[:, None]).as_matrix()
    legs = {j for leg in tgt.legs for j in sk.subtree(leg.chain[0])}
    for j in [tgt.hips] + list(sk.subtree(pivot)):
        if j not in legs:
            rot[:, j] = turn @ rot[:, j]
    return theta
