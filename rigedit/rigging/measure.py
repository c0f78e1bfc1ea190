"""Measurements of a retarget: bone-direction agreement, foot slip and floor clearance."""
from __future__ import annotations

import numpy as np

from .contacts import runs

__all__ = ["direction_errors", "foot_slip", "lowest_foot", "target_foot_points",
           "source_foot_points", "GROUPS"]

#: "feet" (foot and toe bones) are reported apart: their pitch is transferred relative to each
#: figure's flat foot, not copied (see :mod:`.retarget`), so they differ by design.
GROUPS = ("arms", "legs", "spine", "head", "feet")


def _group(slot):
    if slot is None:
        return None
    if slot.startswith(("clavicle", "upper_arm", "forearm", "hand")):
        return "arms"
    if slot.startswith(("thigh", "shin")):
        return "legs"
    if slot.startswith(("foot", "toe")):
        return "feet"
    if slot in ("neck", "head"):
        return "head"
    return "spine"


def direction_errors(result, mats=None):
    """Mean angle (degrees) between each mapped target bone and its source bone, in model
    space, over all frames, per group (arms, legs, spine, head, feet).

    Parameters
    ----------
    result : RetargetResult
    mats : (F, Jt, 4, 4), optional
        Target matrices to measure (``result.mats`` by default).

    Returns
    -------
    errors : dict[str, float]
        Group -> mean angle; ``"worst"`` -> the largest single-frame angle outside the feet.
    """
    from .retarget import _end_points

    mats = result.mats if mats is None else mats
    tgt = result.target_calibration
    slot_of = {j: k for k, j in tgt.slots.items()}
    spine = set(tgt.chains["spine"])
    neck = set(tgt.chains["neck"])
    per, worst = {g: [] for g in GROUPS}, 0.0
    for j, t_spec, s, s_spec in result.pairs:
        g = _group(slot_of.get(j)) or ("spine" if j in spine else "head" if j in neck
                                       else None)
        if g is None:
            continue
        vt = _end_points(mats, t_spec) - mats[:, j, :3, 3]
        vs = _end_points(result.source_mats, s_spec) - result.source_mats[:, s, :3, 3]
        cos = np.sum(vt * vs, axis=1) / (np.linalg.norm(vt, axis=1) * np.linalg.norm(vs, axis=1))
        ang = np.degrees(np.arccos(np.clip(cos, -1, 1)))
        per[g].append(ang.mean())
        if g != "feet":
            worst = max(worst, float(ang.max()))
    out = {g: float(np.mean(v)) if v else float("nan") for g, v in per.items()}
    out["worst"] = worst
    return out


def foot_slip(points, contact):
    """Horizontal path length of each contact point while in contact, per contact.

    Parameters
    ----------
    points : (F, P, 3) float64
    contact : (F, P) bool

    Returns
    -------
    slips : (C,) float64
        One value per contact run (same units as ``points``).
    """
    out = []
    for p in range(contact.shape[1]):
        for a, b in runs(contact[:, p]):
            step = np.diff(points[a:b, p][:, [0, 2]], axis=0)
            out.append(float(np.linalg.norm(step, axis=1).sum()))
    return np.array(out)


def lowest_foot(result, mats=None):
    """Lowest foot point (foot and toe joints and their tails) over the clip, relative to the
    target's floor (its lowest foot point at rest); negative means below."""
    mats = result.mats if mats is None else mats
    tgt = result.target_calibration
    return float(tgt.foot_points(mats)[..., 1].min() - tgt.floor)


def target_foot_points(result, mats=None):
    """(F, 4, 3) target left/right ankle and toe joints (the contact points)."""
    mats = result.mats if mats is None else mats
    return mats[:, result.target_calibration.contacts][..., :3, 3]


def source_foot_points(result):
    """(F, 4, 3) source left/right ankle and toe joints after the facing turn."""
    return result.source_mats[:, result.source_calibration.contacts][..., :3, 3]
