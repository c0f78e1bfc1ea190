"""Measurements of a retarget: bone-direction agreement, foot slip and floor clearance."""
from __future__ import annotations

import numpy as np

from .contacts import runs
from .transfer import end_points

__all__ = ["direction_errors", "foot_slip", "lowest_foot", "target_foot_points",
           "source_foot_points"]


def direction_errors(result, mats=None):
    """Mean angle (degrees) between each mapped target bone and its source bone, in model
    space, over all frames, per group of the target calibration (humanoids: arms, legs,
    spine, head, feet, the feet's pitch being relative to each flat foot by design; other
    skeletons: legs, spine, head (neck and head), tail).

    Parameters
    ----------
    result : RetargetResult
    mats : (F, Jt, 4, 4), optional
        Target matrices to measure (``result.mats`` by default).

    Returns
    -------
    errors : dict[str, float]
        Group -> mean angle (NaN for a group without bones); ``"worst"`` -> the largest
        single-frame angle outside the feet.
    """
    mats = result.mats if mats is None else mats
    tgt = result.target_calibration
    per, worst = {g: [] for g in tgt.groups}, 0.0
    for j, t_spec, s, s_spec in result.pairs:
        g = tgt.group(j)
        if g is None:
            continue
        vt = end_points(mats, t_spec) - mats[:, j, :3, 3]
        vs = end_points(result.source_mats, s_spec) - result.source_mats[:, s, :3, 3]
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
    """(F, P, 3) target contact points (humanoids: left/right ankle and toe joints; others:
    each leg's foot leaf), the columns of ``result.contact``."""
    mats = result.mats if mats is None else mats
    return mats[:, result.target_contacts][..., :3, 3]


def source_foot_points(result):
    """(F, P, 3) the source's contact points matching :func:`target_foot_points`, after the
    facing turn."""
    return result.source_mats[:, result.source_contacts][..., :3, 3]
