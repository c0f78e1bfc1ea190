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
90 degrees that brings its facing onto the target's (:mod:`.facing`): the rest's (heel to toe;
hind feet to fore feet) where the rest stands, else its hips' over all frames of the clip; a
calibration pose that is not the rest faces where its pelvis does (mid-stride the feet do
not), so the target's hips face as the source's do relative to their path.

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

from ...animation.clip import Clip
from ...progress import adapt
from .bake import assemble, to_clip
from .bare import bare_result
from .calibrate import calibrate, model_stack
from .contacts import clean_feet as hold_feet, clean_legs, detect_contacts
from .facing import clip_forward, face_by_hips, facing_doubt, heading_degrees
from .limbs import LegCalibration, ground, leg_contacts
from .name_map import auto_map
from .pitch import pitch_body
from .soles import hold_soles, source_clearance
from .transfer import transfer_rotations
from .tree_map import leg_map, legs_agree

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
    facing_note : str
        Why the facing turn may be wrong (:func:`.facing.facing_doubt`), or "" when sure.
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
    facing_note: str = ""


def _sample_times(clip):
    times = clip.key_times()
    if len(times) < 2 or clip.duration <= 0:
        return np.array([0.0]) if clip.duration <= 0 else np.arange(0, clip.duration + 1e-9,
                                                                    1 / 30)
    steps = np.diff(times)
    if np.ptp(steps) > 1e-4 * steps.mean() or steps.mean() > 1 / 15:
        times = np.arange(0.0, clip.duration + 1e-9, 1 / 30)
    return times


def _facing(src, tgt, smats):
    """Turn about +Y (multiple of 90 degrees) taking the source clip's forward (its rest's,
    else its hips' over all frames ``smats``: :func:`.facing.clip_forward`) to the
    target's."""
    a = heading_degrees(tgt.forward) - heading_degrees(clip_forward(src, smats))
    deg = float(np.round(a / 90.0) * 90.0) % 360.0
    return deg, Rotation.from_euler("y", deg, degrees=True).as_matrix()


def retarget(source_rig, source_clip, target_rig, map=None, name=None, clean_feet=True,
             progress=None):
    """Retarget ``source_clip`` of ``source_rig`` onto ``target_rig`` (two humanoids, or
    any two skeletons with legs on the floor whose joints share names or are mapped).

    Parameters
    ----------
    source_rig, target_rig : Rig
    source_clip : Clip or str
        A clip of the source (or its name).
    map : dict[str, str], optional
        Source joint -> target joint; found automatically when omitted (:func:`auto_map`
        for two humanoids, else :func:`rigedit.rigging.retarget.tree_map.leg_map`: equal names,
        or the trees' shape for two skeletons of the same build).
    name : str, optional
        The new clip's name (the source clip's by default).
    clean_feet : bool
        Hold feet still during the source's contacts and keep them above the floor.
    progress : callable(fraction, stage), optional
        :mod:`rigedit.progress`'s protocol, called between the steps (stages
        ``"calibrate"``, ``"map"``, ``"transfer"``, ``"feet"``, ``"clip"``); raising
        :class:`rigedit.progress.Cancelled` there stops the retarget.

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
    return retarget_result(source_rig, source_clip, target_rig, map, name, clean_feet,
                           progress=progress).clip


def retarget_result(source_rig, source_clip, target_rig, map=None, name=None,
                    clean_feet=True, source_what="source", target_what="target",
                    progress=None):
    """As :func:`retarget`, returning a :class:`RetargetResult` (the map, calibrations,
    contacts and the model matrices before and after the foot clean-up).

    Over 80 lines: the retarget's steps in their order, each a call, kept in one place
    so that the order (calibrate, map, facing, contacts, transfer, feet, soles) reads
    straight down."""
    report = adapt(progress, "retarget")
    report(0.0, "calibrate")
    if isinstance(source_clip, str):
        source_clip = source_rig.clips[source_clip]
    ssk, tsk = source_rig.skeleton, target_rig.skeleton
    try:
        src, tgt = _calibrate_pair(ssk, [source_clip], tsk, list(target_rig.clips.values()),
                                   source_what, target_what)
    except ValueError as exc:  # no legs found: two rigs of one family still map by name
        fields = bare_result(source_rig, source_clip, target_rig, map, name,
                             _sample_times(source_clip), source_what, target_what, str(exc))
        if fields is None:
            raise
        report(1.0, "clip")
        return RetargetResult(**fields)
    report(0.2, "map")
    humanoid = src.kind == "humanoid"
    if map is None:
        map = auto_map(ssk, src.points, tsk, tgt.points, source_what, target_what) \
            if humanoid else leg_map(src, tgt)
    inverse = _inverse_map(map, src, tgt, source_what, target_what)
    times = _sample_times(source_clip)
    smats = model_stack(ssk, source_clip, times)
    # a pose that is not the rest (mid-stride) faces where its pelvis does, not its feet
    face_by_hips(src)
    face_by_hips(tgt)
    facing, rf = _facing(src, tgt, smats)
    facing_note = facing_doubt(src, smats, times)
    turn = np.eye(4)
    turn[:3, :3] = rf
    smats = turn @ smats
    scal = turn @ src.mats
    s_feet = smats[:, src.contacts][..., :3, 3]
    # the motion's own floor: a low percentile of the lowest foot point per frame
    s_floor = float(np.percentile(s_feet[..., 1].min(axis=1), 5)) if len(times) > 1 \
        else src.floor
    rest_h = scal[src.contacts, 1, 3] - src.joint_floor
    contact = detect_contacts(s_feet - [0, s_floor, 0], rest_h, times, src.hip_height)
    s_points = src.contacts
    if not humanoid:
        contact, s_points, s_legs = leg_contacts(src, tgt, inverse, contact)
    report(0.4, "transfer")
    rot, pairs = transfer_rotations(src, tgt, inverse, smats, scal, rf,
                                    contact if humanoid else None)
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
        shift, heights = ground(src, tgt, smats, raw, s_legs, scale)
        hips_t[:, 1] += shift
        raw = assemble(tsk, rot, hips, hips_t)
        heights += shift
    mats = raw
    if clean_feet:
        report(0.6, "feet")
        if humanoid:
            rot, drop = hold_feet(tsk, tgt, rot, raw, contact, tgt.contacts, times, inverse)
        else:
            # fore and hind legs of other proportions than the source's: pitch the body
            pitched = raw if pitch_body(src, tgt, rot, raw, smats, s_legs) is None else \
                assemble(tsk, rot, hips, hips_t)
            rot, drop = clean_legs(tsk, tgt, rot, pitched, contact, tgt.legs, times,
                                   inverse, heights)
        hips_t = hips_t - np.c_[np.zeros_like(drop), drop, np.zeros_like(drop)]
        mats = assemble(tsk, rot, hips, hips_t)
        # what the user sees is the skin: its soles on the floor, not only the joints
        clear = source_clearance(src, smats, s_floor, s_points, scale, source_rig)
        rot, hips_t, mats = hold_soles(target_rig, tgt, rot, hips_t, mats, contact, clear,
                                       times, inverse, target_what)
    clip = to_clip(tsk, mats, rot, times, name or source_clip.name, source_clip, hips,
                   tgt.points[hips])
    report(1.0, "clip")
    return RetargetResult(clip, dict(map), src, tgt, facing, scale, times, smats, raw, mats,
                          contact, s_floor, pairs, list(s_points), list(tgt.contacts),
                          facing_note)


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
    legs = "" if tgt.kind == "humanoid" or legs_agree(src, tgt) else \
        "; their legs differ ({} legs from the hips and {} from elsewhere against {} and {})" \
        .format(*src.leg_counts(), *tgt.leg_counts())
    if not mapping:
        raise ValueError(f"{source_what}: none of its {len(ssk)} joints maps onto "
                         f"{target_what}: they are not two humanoids (matched by structure) "
                         f"and share no joint names{legs}; give a joint map (--map)")
    inverse = {tsk.index[t]: ssk.index[s] for s, t in mapping.items()}
    need = ("hips",) if tgt.kind != "humanoid" else \
        ("hips", "thigh_L", "shin_L", "foot_L", "thigh_R", "shin_R", "foot_R")
    for slot in need:
        j = tgt.hips if slot == "hips" else tgt.slots[slot]
        if j not in inverse:
            raise ValueError(f"{source_what}: no joint maps onto the target's {slot} "
                             f"({tsk.names[j]}) in {target_what}" +
                             ("" if tgt.kind == "humanoid" else
                              f" ({len(mapping)} joints mapped{legs}); give a joint map "
                              f"(--map)"))
    return inverse
