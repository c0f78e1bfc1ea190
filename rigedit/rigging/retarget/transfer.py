"""Bone directions: where each bone points, and the target's model rotations that point
each mapped bone where its source bone points (see :mod:`.retarget`)."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from .calibrate import rotations_of, swing
from ...model.transforms import unit
from .chains import distribute_bend
from .limbs import ancestors

__all__ = ["transfer_rotations", "end_spec", "end_points", "pitch_of", "pitched",
           "FLAT_AGREE", "SAME_FOOT"]

#: Degrees within which the source's rest foot and its median foot during contacts are taken
#: for the same flat foot (then the rest's is used).
FLAT_AGREE = 15.0
#: Degrees within which two rests' foot bones pitch alike (with their lengths in the same
#: proportion to the legs) for the feet to count as one build.
SAME_FOOT = 0.5


def end_spec(skeleton, calib, j, mapped, next_in_chain):
    """Where bone ``j`` points: ``(joint, local point)`` whose model position is its end.
    The next mapped joint down its chain, else the first mapped descendant, else its tail,
    else the farthest point of its subtree at calibration, else None."""
    if next_in_chain is not None:
        return next_in_chain, np.zeros(3)
    for d in skeleton.subtree(j)[1:]:
        if d in mapped and not any(a in mapped for a in _between(skeleton, j, d)):
            return int(d), np.zeros(3)
    if np.all(np.isfinite(skeleton.tails[j])):
        return j, (skeleton.inverse_bind_matrices[j] @ np.r_[skeleton.tails[j], 1])[:3]
    sub = skeleton.subtree(j)[1:]
    if len(sub):
        far = sub[np.argmax(np.linalg.norm(calib.points[sub] - calib.points[j], axis=1))]
        local = np.linalg.inv(calib.mats[j]) @ np.r_[calib.points[far], 1.0]
        return j, local[:3]
    return None


def _between(skeleton, top, low):
    out, a = [], skeleton.parents[low]
    while a != top and a >= 0:
        out.append(a)
        a = skeleton.parents[a]
    return out


def end_points(mats, spec):
    joint, local = spec
    return (mats[..., joint, :, :] @ np.r_[local, 1.0])[..., :3]


def transfer_rotations(src, tgt, inverse, smats, scal, rf, contact):
    """The target's model rotations pointing each mapped bone where its source bone points
    (see :mod:`.retarget`).

    Parameters
    ----------
    src, tgt : Calibration or LegCalibration
        The source's and the target's calibrations.
    inverse : dict[int, int]
        Target joint -> source joint.
    smats : (F, Js, 4, 4) float64
        The source's model matrices over the clip, turned to face as the target.
    scal : (Js, 4, 4) float64
        The source's calibration pose, turned alike.
    rf : (3, 3) float64
        That turn (applied here to the source's forward and left).
    contact : (F, 4) bool or None
        Humanoids: the source's contacts (left and right ankle, then toe), for the feet's
        pitch relative to the flat foot.

    Returns
    -------
    rot : (F, Jt, 3, 3) float64
    pairs : list of (int, spec, int, spec)
        The measured pairs ``(joint, end spec, source joint, source end spec)``.
    """
    tsk = tgt.skeleton
    s_rot, sc_rot = rotations_of(smats), rotations_of(scal)
    t_rot_c = rotations_of(tgt.mats)
    s_fwd, s_left = rf @ src.forward, rf @ src.left
    humanoid = tgt.kind == "humanoid"
    # chain order (spine then neck) decides a chest's "next" joint: the neck, not an arm
    chain = [j for j in tgt.chains["spine"] + tgt.chains["neck"] if j in inverse] \
        if humanoid else []
    n_frames, nj = len(smats), len(tsk)
    rot = np.empty((n_frames, nj, 3, 3))
    # an unmapped joint keeps its relation to its parent in the target's calibration pose:
    # the rest's when the rest stands, else that of the clip frame calibrated on (iClone's and
    # Bandai's rests point every bone along one axis: their faces, kept at rest, turned the
    # head's bone to an eye 85 degrees off)
    keep = [t_rot_c[j] if tsk.parents[j] < 0 else t_rot_c[tsk.parents[j]].T @ t_rot_c[j]
            for j in range(len(tsk))]
    # feet and toes: pitch relative to each figure's flat foot, not the same direction (a
    # BVH foot often points more steeply down than a mesh's: copied, the toes would dig in)
    flat = {tgt.slots[f"{part}_{side}"]: contact[:, k] & contact[:, k + 2]
            for k, side in enumerate("LR") for part in ("foot", "toe")
            if f"{part}_{side}" in tgt.slots} if humanoid else {}
    pairs = []
    above_hips = set(ancestors(tsk, tgt.hips))
    for j in range(nj):
        p = tsk.parents[j]
        if j not in inverse:
            rot[:, j] = (rot[:, p] if p >= 0 else np.eye(3)) @ keep[j]
            continue
        s = inverse[j]
        t_spec, s_spec = _end_specs(src, tgt, j, s, inverse, chain)
        vt, vs = _calibration_bones(src, tgt, scal, j, s, t_spec, s_spec, above_hips)
        if vt is not None:
            x, _ = Rotation.align_vectors([vs, s_fwd, s_left], [vt, tgt.forward, tgt.left],
                                          weights=[np.inf, 1.0, 1.0])
        else:
            x, _ = Rotation.align_vectors([s_fwd, s_left], [tgt.forward, tgt.left])
        r = s_rot[:, s] @ (sc_rot[s].T @ x.as_matrix() @ t_rot_c[j])
        # the hips and what carries them (a ground-level root) turn as the source's do: their
        # "bone" to the next joint is no limb
        if vt is not None and j not in above_hips:
            u = t_rot_c[j].T @ vt
            want = end_points(smats, s_spec) - smats[:, s, :3, 3]
            if j in flat:
                want = _flat_foot_pitched(src, tgt, want, flat[j], vt, vs)
            r = swing(r @ u, want) @ r
            pairs.append((j, t_spec, s, s_spec))
        rot[:, j] = r
    if humanoid:
        distribute_bend(tsk, tgt, rot, inverse)
    return rot, pairs


def _end_specs(src, tgt, j, s, inverse, chain):
    """Where target joint ``j``'s bone and its source joint ``s``'s bone point
    (:func:`end_spec` each, the source's to the source joint of the target's end when that
    is another joint): ``(t_spec, s_spec)``, None where a bone has no end. ``chain``: the
    mapped spine and neck joints in order (a chest's next joint is the neck, not an arm);
    a humanoid's hips point to its chest."""
    nxt = chain[chain.index(j) + 1] if j in chain and j != chain[-1] else None
    if tgt.kind == "humanoid" and j == tgt.hips:
        nxt = tgt.slots["chest"]
    t_spec = end_spec(tgt.skeleton, tgt, j, inverse, nxt)
    s_spec = None
    if t_spec is not None:
        if t_spec[0] != j:
            s_spec = (inverse[t_spec[0]], np.zeros(3))
        else:
            s_spec = end_spec(src.skeleton, src, s, set(), None)
    return t_spec, s_spec


def _calibration_bones(src, tgt, scal, j, s, t_spec, s_spec, above_hips):
    """``(vt, vs)``: the (3,) bones of target joint ``j`` and source joint ``s`` in their
    calibration poses (``scal``: the source's (Js, 4, 4)), or ``(None, None)`` where either
    has no bone to align: no end, one shorter than 1e-4 of the hip height, or a joint above
    the hips (what carries them has no bone: its "bone" to the hips changes with the
    figure's proportions)."""
    if s_spec is None or not (j == tgt.hips or j not in above_hips):
        return None, None
    vt = end_points(tgt.mats, t_spec) - tgt.points[j]
    vs = end_points(scal, s_spec) - scal[s, :3, 3]
    if np.linalg.norm(vt) < 1e-4 * tgt.hip_height or \
            np.linalg.norm(vs) < 1e-4 * src.hip_height:
        return None, None
    return vt, vs


def _flat_foot_pitched(src, tgt, want, flat, vt, vs):
    """A foot's or toe's source directions ``want`` (F, 3) turned by the difference of the
    two figures' flat-foot pitches, so that the target's foot pitches from its flat foot as
    the source's does from its own. ``flat`` (F,) bool: the source's contacts of that foot
    (its median pitch there is the source's flat foot); ``vt``, ``vs``: the (3,) calibration
    bones."""
    pitch = pitch_of(want[flat]) if flat.any() else pitch_of(vs)
    s_flat = float(np.median(pitch))
    # a standing rest whose foot agrees with the clip's flat foot is the better measure of
    # it (the median over contacts carries the foot's roll and curled toes: Xbot's toes
    # stand 5-7 degrees up in its own clips): so a character's own clip keeps its feet
    # exactly
    if src.source == "rest" and abs(s_flat - pitch_of(vs)) < np.radians(FLAT_AGREE):
        s_flat = float(pitch_of(vs))
    # a target calibrated on a clip's frame (its rest does not stand) has no known flat
    # foot, and a foot built as the source's (the same pitch in both rests, the same length
    # for the leg) has the source's: the foot points as the source's (CMU 131_01 onto
    # itself: its toes point 11-18 degrees off their rest during its contacts)
    same = tgt.source == src.source and \
        abs(pitch_of(vt) - pitch_of(vs)) < np.radians(SAME_FOOT) and \
        abs(np.linalg.norm(vt) / tgt.hip_height
            - np.linalg.norm(vs) / src.hip_height) < 1e-3
    t_flat = pitch_of(vt) if tgt.source == "rest" and not same else s_flat
    return pitched(want, s_flat - t_flat)


def pitch_of(v):
    """Angle (radians) of direction(s) ``v`` (..., 3) below the horizontal."""
    v = unit(v)
    return np.arcsin(np.clip(-v[..., 1], -1.0, 1.0))


def pitched(v, delta):
    """Directions ``v`` (F, 3) turned up by ``delta`` radians about their horizontal normal."""
    axis = unit(np.cross(v, [0.0, 1.0, 0.0]))
    rv = Rotation.from_rotvec(axis * delta)
    return rv.apply(v)
