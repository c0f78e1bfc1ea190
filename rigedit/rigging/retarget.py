"""Retarget a clip from one skeleton onto another: two humanoids, two quadrupeds, or any
two skeletons with legs and a joint map.

Two humanoids are calibrated by their slots (:mod:`.name_map`: legs, spine, arms found by
structure, so CMU, Bandai, Mixamo and glTF names map automatically); any other pair by its
legs (:mod:`.limbs`: leaf chains that reach the floor in a standing pose), mapped by equal
joint names (an auto-rigged character keeps its template's names, so the map is the
identity) or by a given map.

Each mapped target bone is made to point, in model space, the way its source bone points
(from the joint to its next mapped joint, or to its tail), frame by frame; local Euler angles
are never copied, so rest poses may differ (T-pose against A-pose, other bone rolls, a BVH
rest lying along one axis). With ``S(t)`` a source joint's model rotation, ``S_c`` its
rotation in the source's calibration pose, ``T_c`` the target joint's in its own and ``X`` the
rotation that takes the target's calibration bone onto the source's (bone direction exact,
body forward and left as close as they go), the target joint's model rotation is
``T(t) = W(t) · S(t) · S_c⁻¹ · X · T_c`` where ``W(t)`` is the smallest swing that makes the
bone direction exact in that frame (it differs from identity where unmapped source joints
between two mapped ones bend). When both rests stand alike, ``X`` is the identity and this is
``S(t) · S_c⁻¹ · T_c``. The source is first turned about the vertical axis by the multiple of
90 degrees that brings its facing (heel to toe; hind feet to fore feet) onto the target's.

The hips follow the source's hips scaled by the ratio of hip heights (target / source, each
the height of the thigh joints standing straight: the leg length; for a quadruped its hind
legs'), both horizontally and vertically, above the target's floor (its lowest foot joint at
rest); vertically it is the thigh joints that are placed, so a deeper pelvis does not
shorten the legs' reach. Then the feet are cleaned up (:mod:`.contacts`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from ..animation.clip import Clip
from .bake import assemble, to_clip
from .calibrate import calibrate, foot_points, model_stack, rotations_of, swing, unit
from .chains import distribute_bend
from .contacts import clean_feet as hold_feet, clean_legs, detect_contacts
from .limbs import LegCalibration
from .name_map import auto_map, name_pairs

__all__ = ["retarget", "retarget_result", "RetargetResult"]


@dataclass
class RetargetResult:
    """A retargeted clip and what was decided and measured on the way.

    Attributes
    ----------
    clip : Clip
    mapping : dict[str, str]
        Source joint -> target joint.
    source_calibration, target_calibration : Calibration
    facing_degrees : float
        Turn about +Y applied to the source (a multiple of 90).
    scale : float
        Target hip height / source hip height.
    times : (F,) float64
    source_mats : (F, Js, 4, 4) float64
        Source model matrices after the facing turn.
    raw_mats, mats : (F, Jt, 4, 4) float64
        Target model matrices before and after the foot clean-up.
    contact : (F, P) bool
        Source contacts: for humanoids of the left ankle, right ankle, left toe, right toe;
        otherwise of the source foot under each target leg (in the target's leg order).
    source_floor : float
    pairs : list
        ``(target joint, end, source joint, source end)`` of each bone pointed like its
        source bone.
    source_contacts, target_contacts : list of int
        The source and target joints of the contact points (the columns of ``contact``).
    """

    clip: Clip
    mapping: dict
    source_calibration: object
    target_calibration: object
    facing_degrees: float
    scale: float
    times: np.ndarray
    source_mats: np.ndarray
    raw_mats: np.ndarray
    mats: np.ndarray
    contact: np.ndarray
    source_floor: float
    pairs: list = field(default_factory=list)
    source_contacts: list = field(default_factory=list)
    target_contacts: list = field(default_factory=list)


def _sample_times(clip):
    times = clip.key_times()
    if len(times) < 2 or clip.duration <= 0:
        return np.array([0.0]) if clip.duration <= 0 else np.arange(0, clip.duration + 1e-9,
                                                                    1 / 30)
    steps = np.diff(times)
    if np.ptp(steps) > 1e-4 * steps.mean() or steps.mean() > 1 / 15:
        times = np.arange(0.0, clip.duration + 1e-9, 1 / 30)
    return times


def _end_spec(skeleton, calib, j, mapped, next_in_chain):
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


def _end_points(mats, spec):
    joint, local = spec
    return (mats[..., joint, :, :] @ np.r_[local, 1.0])[..., :3]


def _facing(src, tgt):
    """Turn about +Y (multiple of 90 degrees) taking the source's forward to the target's."""
    a = np.arctan2(tgt.forward[0], tgt.forward[2]) - np.arctan2(src.forward[0], src.forward[2])
    deg = float(np.round(np.degrees(a) / 90.0) * 90.0) % 360.0
    return deg, Rotation.from_euler("y", deg, degrees=True).as_matrix()


def retarget(source_rig, source_clip, target_rig, map=None, name=None, clean_feet=True):
    """Retarget ``source_clip`` of ``source_rig`` onto ``target_rig`` (two humanoids, or
    any two skeletons with legs on the floor whose joints share names or are mapped).

    Parameters
    ----------
    source_rig, target_rig : Rig
    source_clip : Clip or str
        A clip of the source (or its name).
    map : dict[str, str], optional
        Source joint -> target joint; found automatically when omitted (:func:`auto_map`
        for two humanoids, else :func:`name_pairs`: equal names).
    name : str, optional
        The new clip's name (the source clip's by default).
    clean_feet : bool
        Hold feet still during the source's contacts and keep them above the floor.

    Returns
    -------
    clip : Clip
        On the target's skeleton; unmapped joints keep their rest transform.

    Raises
    ------
    ValueError
        Naming the file: when either skeleton has no legs on the floor, when the map names
        unknown joints, is empty or leaves the target's hips (a humanoid's legs) unmapped.
    """
    return retarget_result(source_rig, source_clip, target_rig, map, name, clean_feet).clip


def retarget_result(source_rig, source_clip, target_rig, map=None, name=None,
                    clean_feet=True, source_what="source", target_what="target"):
    """As :func:`retarget`, returning a :class:`RetargetResult` (the map, calibrations,
    contacts and the model matrices before and after the foot clean-up)."""
    if isinstance(source_clip, str):
        source_clip = source_rig.clips[source_clip]
    ssk, tsk = source_rig.skeleton, target_rig.skeleton
    src, tgt = _calibrate_pair(ssk, [source_clip], tsk, list(target_rig.clips.values()),
                               source_what, target_what)
    humanoid = src.kind == "humanoid"
    if map is None:
        map = auto_map(ssk, src.points, tsk, tgt.points, source_what, target_what) \
            if humanoid else name_pairs(ssk, tsk)
    inverse = _inverse_map(map, src, tgt, source_what, target_what)
    facing, rf = _facing(src, tgt)
    times = _sample_times(source_clip)
    turn = np.eye(4)
    turn[:3, :3] = rf
    smats = turn @ model_stack(ssk, source_clip, times)
    scal = turn @ src.mats
    s_feet = smats[:, src.contacts][..., :3, 3]
    # the motion's own floor: a low percentile of the lowest foot point per frame
    s_floor = float(np.percentile(s_feet[..., 1].min(axis=1), 5)) if len(times) > 1 \
        else src.floor
    rest_h = scal[src.contacts, 1, 3] - src.joint_floor
    contact = detect_contacts(s_feet - [0, s_floor, 0], rest_h, times, src.hip_height)
    s_points = src.contacts
    if not humanoid:
        contact, s_points, s_legs = _leg_contacts(src, tgt, inverse, contact)
    rot, pairs = _transfer(src, tgt, inverse, smats, scal, rf, contact if humanoid else None)
    scale = tgt.hip_height / src.hip_height
    hips = tgt.hips
    hips_s = smats[:, inverse[hips], :3, 3]
    if humanoid:
        hips_t = hips_s * scale
    else:  # relative to each rest: a quadruped's pelvis stands far from the origin
        hips_t = tgt.points[hips] + (hips_s - scal[inverse[hips], :3, 3]) * scale
    # the thigh joints go where the source's go, scaled: the pelvis depth is each one's own
    hips_t[:, 1] = tgt.joint_floor + (hips_s[:, 1] - s_floor - src.hip_offset) * scale \
        + tgt.hip_offset
    raw = assemble(tsk, rot, hips, hips_t)
    if not humanoid:
        shift, heights = _ground(src, tgt, smats, raw, s_legs, scale)
        hips_t[:, 1] += shift
        raw = assemble(tsk, rot, hips, hips_t)
        heights += shift
    mats = raw
    if clean_feet:
        if humanoid:
            rot, drop = hold_feet(tsk, tgt, rot, raw, contact, tgt.contacts, times, inverse)
        else:
            rot, drop = clean_legs(tsk, tgt, rot, raw, contact, tgt.legs, times, inverse,
                                   heights)
        hips_t = hips_t - np.c_[np.zeros_like(drop), drop, np.zeros_like(drop)]
        mats = assemble(tsk, rot, hips, hips_t)
    clip = to_clip(tsk, mats, rot, times, name or source_clip.name, source_clip, hips,
                   tgt.points[hips])
    return RetargetResult(clip, dict(map), src, tgt, facing, scale, times, smats, raw, mats,
                          contact, s_floor, pairs, list(s_points), list(tgt.contacts))


def _calibrate_pair(ssk, s_clips, tsk, t_clips, s_what, t_what):
    """Both skeletons as humanoids (slots, :class:`Calibration`) when both stand like one;
    otherwise both by their legs (:class:`LegCalibration`: any skeleton with feet)."""
    try:
        return calibrate(ssk, s_clips, s_what), calibrate(tsk, t_clips, t_what)
    except ValueError:
        pass
    return (calibrate(ssk, s_clips, s_what, LegCalibration),
            calibrate(tsk, t_clips, t_what, LegCalibration))


def _inverse_map(mapping, src, tgt, source_what, target_what):
    """Target joint index -> source joint index, after checking the map's names and that it
    reaches what the retarget needs (the hips; a humanoid's legs)."""
    ssk, tsk = src.skeleton, tgt.skeleton
    for names, sk, role, what in ((mapping.keys(), ssk, "source", source_what),
                                  (mapping.values(), tsk, "target", target_what)):
        unknown = [nm for nm in names if nm not in sk.index]
        if unknown:
            raise ValueError(f"{what}: the joint map names {role} joints it does not have: "
                             f"{', '.join(repr(nm) for nm in unknown[:5])}")
    if len(set(mapping.values())) != len(mapping):
        raise ValueError(f"{target_what}: the joint map names a target joint twice")
    if not mapping:
        raise ValueError(f"{source_what}: none of its {len(ssk)} joints maps onto "
                         f"{target_what}: they are not two humanoids (matched by structure) "
                         f"and share no joint names; give a joint map (--map)")
    inverse = {tsk.index[t]: ssk.index[s] for s, t in mapping.items()}
    need = ("hips",) if tgt.kind != "humanoid" else \
        ("hips", "thigh_L", "shin_L", "foot_L", "thigh_R", "shin_R", "foot_R")
    for slot in need:
        j = tgt.hips if slot == "hips" else tgt.slots[slot]
        if j not in inverse:
            raise ValueError(f"{source_what}: no joint maps onto the target's {slot} "
                             f"({tsk.names[j]}) in {target_what}" +
                             ("" if tgt.kind == "humanoid" else
                              f" ({len(mapping)} joint names in common); give a joint map "
                              f"(--map)"))
    return inverse


def _leg_contacts(src, tgt, inverse, contact):
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


def _ground(src, tgt, smats, raw, s_legs, scale):
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
    s_ground = np.percentile(src.foot_points(smats)[..., 1].min(axis=1), 5)
    shift = tgt.floor - np.percentile(tgt.foot_points(raw)[..., 1].min(axis=1), 5)
    heights = raw[:, tgt.contacts, 1, 3].copy()
    for i, (leg, k) in enumerate(zip(tgt.legs, s_legs)):
        if k is None:
            continue
        t_low = foot_points(tgt.skeleton, leg.foot, raw)[..., 1].min(axis=1)
        s_low = foot_points(src.skeleton, src.legs[k].foot, smats)[..., 1].min(axis=1)
        heights[:, i] += tgt.floor - shift + scale * (s_low - s_ground) - t_low
    return shift, heights


def _transfer(src, tgt, inverse, smats, scal, rf, contact):
    """Model rotations (F, Jt, 3, 3) of the target pointing each mapped bone where its
    source bone points (see the module docstring), and the measured pairs
    ``(joint, end spec, source joint, source end spec)``. ``contact`` (humanoids): the
    source contacts, for the feet's pitch relative to the flat foot."""
    ssk, tsk = src.skeleton, tgt.skeleton
    s_rot, sc_rot = rotations_of(smats), rotations_of(scal)
    t_rot_c = rotations_of(tgt.mats)
    s_fwd, s_left = rf @ src.forward, rf @ src.left
    humanoid = tgt.kind == "humanoid"
    # chain order (spine then neck) decides a chest's "next" joint: the neck, not an arm
    chain = [j for j in tgt.chains["spine"] + tgt.chains["neck"] if j in inverse] \
        if humanoid else []
    n_frames, nj = len(smats), len(tsk)
    rot = np.empty((n_frames, nj, 3, 3))
    rest_rot = Rotation.from_quat(tsk.rest_rotation).as_matrix()
    # feet and toes: pitch relative to each figure's flat foot, not the same direction (a
    # BVH foot often points more steeply down than a mesh's: copied, the toes would dig in)
    flat = {tgt.slots[f"{part}_{side}"]: contact[:, k] & contact[:, k + 2]
            for k, side in enumerate("LR") for part in ("foot", "toe")
            if f"{part}_{side}" in tgt.slots} if humanoid else {}
    pairs = []
    above_hips, a = set(), tgt.hips
    while a >= 0:
        above_hips.add(a)
        a = tsk.parents[a]
    for j in range(nj):
        p = tsk.parents[j]
        if j not in inverse:
            rot[:, j] = (rot[:, p] if p >= 0 else np.eye(3)) @ rest_rot[j]
            continue
        s = inverse[j]
        nxt = chain[chain.index(j) + 1] if j in chain and j != chain[-1] else None
        if humanoid and j == tgt.hips:
            nxt = tgt.slots["chest"]
        t_spec = _end_spec(tsk, tgt, j, inverse, nxt)
        s_spec = None
        if t_spec is not None:
            if t_spec[0] != j:
                s_spec = (inverse[t_spec[0]], np.zeros(3))
            else:
                s_spec = _end_spec(ssk, src, s, set(), None)
        vt = vs = None
        if s_spec is not None:
            vt = _end_points(tgt.mats, t_spec) - tgt.points[j]
            vs = _end_points(scal, s_spec) - scal[s, :3, 3]
            if np.linalg.norm(vt) < 1e-4 * tgt.hip_height or \
                    np.linalg.norm(vs) < 1e-4 * src.hip_height:
                vt = vs = None
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
            want = _end_points(smats, s_spec) - smats[:, s, :3, 3]
            if j in flat:
                pitch = _pitch(want[flat[j]]) if flat[j].any() else _pitch(vs)
                want = _pitched(want, float(np.median(pitch)) - _pitch(vt))
            r = swing(r @ u, want) @ r
            pairs.append((j, t_spec, s, s_spec))
        rot[:, j] = r
    if humanoid:
        distribute_bend(tsk, tgt, rot, inverse)
    return rot, pairs


def _pitch(v):
    """Angle (radians) of direction(s) ``v`` (..., 3) below the horizontal."""
    v = unit(v)
    return np.arcsin(np.clip(-v[..., 1], -1.0, 1.0))


def _pitched(v, delta):
    """Directions ``v`` (F, 3) turned up by ``delta`` radians about their horizontal normal."""
    axis = unit(np.cross(v, [0.0, 1.0, 0.0]))
    rv = Rotation.from_rotvec(axis * delta)
    return rv.apply(v)
