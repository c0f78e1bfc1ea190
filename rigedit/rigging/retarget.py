"""Retarget a clip from one humanoid skeleton onto another.

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
90 degrees that brings its facing (heel to toe) onto the target's.

The hips follow the source's hips scaled by the ratio of hip heights (target / source, each
the height of the thigh joints standing straight: the leg length), both horizontally and
vertically, above the target's floor (its lowest foot joint at rest); vertically it is the
thigh joints that are placed, so a deeper pelvis does not shorten the legs' reach. Then the feet are cleaned up
(:mod:`.contacts`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from ..animation.clip import Clip, Track
from .calibrate import calibrate, model_stack, rotations_of, swing, unit
from .chains import distribute_bend
from .contacts import clean_feet as hold_feet, detect_contacts
from .name_map import auto_map

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
    contact : (F, 4) bool
        Source contacts of the left ankle, right ankle, left toe, right toe.
    source_floor : float
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
    """Retarget ``source_clip`` of ``source_rig`` onto ``target_rig``.

    Parameters
    ----------
    source_rig, target_rig : Rig
    source_clip : Clip or str
        A clip of the source (or its name).
    map : dict[str, str], optional
        Source joint -> target joint; found automatically (:func:`auto_map`) when omitted.
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
        When either skeleton has no humanoid legs, spine and arms, or the map is empty.
    """
    return retarget_result(source_rig, source_clip, target_rig, map, name, clean_feet).clip


def retarget_result(source_rig, source_clip, target_rig, map=None, name=None,
                    clean_feet=True, source_what="source", target_what="target"):
    """As :func:`retarget`, returning a :class:`RetargetResult` (the map, calibrations,
    contacts and the model matrices before and after the foot clean-up)."""
    if isinstance(source_clip, str):
        source_clip = source_rig.clips[source_clip]
    ssk, tsk = source_rig.skeleton, target_rig.skeleton
    src = calibrate(ssk, [source_clip], source_what)
    tgt = calibrate(tsk, list(target_rig.clips.values()), target_what)
    if map is None:
        map = auto_map(ssk, src.points, tsk, tgt.points, source_what, target_what)
    if not map:
        raise ValueError(f"{source_what}: no joint maps onto {target_what}")
    inverse = {tsk.index[t]: ssk.index[s] for s, t in map.items()}
    for slot in ("hips", "thigh_L", "shin_L", "foot_L", "thigh_R", "shin_R", "foot_R"):
        if tgt.slots[slot] not in inverse:
            raise ValueError(f"{source_what}: no joint maps onto the target's {slot} "
                             f"({tsk.names[tgt.slots[slot]]})")
    facing, rf = _facing(src, tgt)
    times = _sample_times(source_clip)
    smats = model_stack(ssk, source_clip, times)
    turn = np.eye(4)
    turn[:3, :3] = rf
    smats = turn @ smats
    scal = turn @ src.mats
    s_rot, sc_rot = rotations_of(smats), rotations_of(scal)
    t_rot_c = rotations_of(tgt.mats)
    s_fwd, s_left = rf @ src.forward, rf @ src.left
    # chain order (spine then neck) decides a chest's "next" joint: the neck, not an arm
    chain = [j for j in tgt.chains["spine"] + tgt.chains["neck"] if j in inverse]
    n_frames, nj = len(times), len(tsk)
    rot = np.empty((n_frames, nj, 3, 3))
    rest_rot = Rotation.from_quat(tsk.rest_rotation).as_matrix()
    src_feet = src.contacts
    s_feet = smats[:, src_feet][..., :3, 3]
    # the motion's own floor: a low percentile of the lowest foot point per frame
    s_floor = float(np.percentile(s_feet[..., 1].min(axis=1), 5)) if n_frames > 1 else src.floor
    rest_h = scal[src_feet, 1, 3] - src.joint_floor
    contact = detect_contacts(s_feet - [0, s_floor, 0], rest_h, times, src.hip_height)
    # feet and toes: pitch relative to each figure's flat foot, not the same direction (a
    # BVH foot often points more steeply down than a mesh's: copied, the toes would dig in)
    flat = {tgt.slots[f"{part}_{side}"]: contact[:, k] & contact[:, k + 2]
            for k, side in enumerate("LR") for part in ("foot", "toe")
            if f"{part}_{side}" in tgt.slots}
    pairs = []
    for j in range(nj):
        p = tsk.parents[j]
        if j not in inverse:
            rot[:, j] = (rot[:, p] if p >= 0 else np.eye(3)) @ rest_rot[j]
            continue
        s = inverse[j]
        nxt = chain[chain.index(j) + 1] if j in chain and j != chain[-1] else None
        if j == tgt.slots["hips"]:
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
            size = tgt.hip_height
            if np.linalg.norm(vt) < 1e-4 * size or np.linalg.norm(vs) < 1e-4 * src.hip_height:
                vt = vs = None
        if vt is not None:
            x, _ = Rotation.align_vectors([vs, s_fwd, s_left], [vt, tgt.forward, tgt.left],
                                          weights=[np.inf, 1.0, 1.0])
        else:
            x, _ = Rotation.align_vectors([s_fwd, s_left], [tgt.forward, tgt.left])
        a = sc_rot[s].T @ x.as_matrix() @ t_rot_c[j]
        r = s_rot[:, s] @ a
        if vt is not None and j != tgt.slots["hips"]:
            u = t_rot_c[j].T @ vt
            want = _end_points(smats, s_spec) - smats[:, s, :3, 3]
            if j in flat:
                pitch = _pitch(want[flat[j]]) if flat[j].any() else _pitch(vs)
                want = _pitched(want, float(np.median(pitch)) - _pitch(vt))
            r = swing(r @ u, want) @ r
            pairs.append((j, t_spec, s, s_spec))
        rot[:, j] = r
    distribute_bend(tsk, tgt, rot, inverse)
    scale = tgt.hip_height / src.hip_height
    hips_s = smats[:, inverse[tgt.slots["hips"]], :3, 3]
    hips_t = hips_s * scale
    # the thigh joints go where the source's go, scaled: the pelvis depth is each one's own
    hips_t[:, 1] = tgt.joint_floor + (hips_s[:, 1] - s_floor - src.hip_offset) * scale \
        + tgt.hip_offset
    raw = _assemble(tsk, rot, tgt.slots["hips"], hips_t)
    tgt_feet = tgt.contacts
    mats = raw
    if clean_feet:
        rot, drop = hold_feet(tsk, tgt, rot, raw, contact, tgt_feet, times, inverse)
        hips_t = hips_t - np.c_[np.zeros_like(drop), drop, np.zeros_like(drop)]
        mats = _assemble(tsk, rot, tgt.slots["hips"], hips_t)
    clip = _to_clip(tsk, mats, rot, times, name or source_clip.name, source_clip,
                    tgt.slots["hips"], tgt.points[tgt.slots["hips"]])
    return RetargetResult(clip, dict(map), src, tgt, facing, scale, times, smats, raw, mats,
                          contact, s_floor, pairs)


def _pitch(v):
    """Angle (radians) of direction(s) ``v`` (..., 3) below the horizontal."""
    v = unit(v)
    return np.arcsin(np.clip(-v[..., 1], -1.0, 1.0))


def _pitched(v, delta):
    """Directions ``v`` (F, 3) turned up by ``delta`` radians about their horizontal normal."""
    axis = unit(np.cross(v, [0.0, 1.0, 0.0]))
    rv = Rotation.from_rotvec(axis * delta)
    return rv.apply(v)


def _assemble(skeleton, rot, hips, hips_pos):
    """Model matrices from model rotations, rest translations and the hips' model position.

    Returns
    -------
    mats : (F, J, 4, 4) float64
    """
    n_frames, nj = rot.shape[:2]
    mats = np.zeros((n_frames, nj, 4, 4))
    mats[..., 3, 3] = 1.0
    for j in range(nj):
        p = skeleton.parents[j]
        mats[:, j, :3, :3] = rot[:, j] * skeleton.rest_scale[j]
        if j == hips:
            mats[:, j, :3, 3] = hips_pos
        elif p >= 0:
            mats[:, j, :3, 3] = (mats[:, p] @ np.r_[skeleton.rest_translation[j], 1.0])[:, :3]
        else:
            mats[:, j, :3, 3] = skeleton.rest_translation[j]
    return mats


def _to_clip(skeleton, mats, rot, times, name, source_clip, hips, hips_rest):
    """Local keys from model matrices: a rotation track per joint whose rotation moves, a
    translation track for the hips; when the hips hang from a non-deforming root (a
    ground-level carrier, as the bundled characters have), the root carries the horizontal
    travel, as in the bundled walks (the recorder's camera follows it)."""
    tracks = {}
    nj = len(skeleton)
    for j in range(nj):
        p = skeleton.parents[j]
        local = rot[:, j] if p < 0 else np.swapaxes(rot[:, p], -1, -2) @ rot[:, j]
        quats = Rotation.from_matrix(local).as_quat()
        if np.allclose(np.abs(quats @ skeleton.rest_rotation[j]), 1.0, atol=1e-9):
            continue
        tracks[(skeleton.names[j], "rotation")] = Track("rotation", times, quats, "slerp")
    p = skeleton.parents[hips]
    world = np.c_[mats[:, hips, :3, 3], np.ones(len(times))]
    if p >= 0 and skeleton.parents[p] < 0 and not skeleton.deform[p]:
        travel = (world[:, :3] - hips_rest) * [1.0, 0.0, 1.0]
        carried = skeleton.rest_translation[p] + travel
        mats = mats.copy()
        mats[:, p, :3, 3] = carried
        tracks[(skeleton.names[p], "translation")] = Track("translation", times, carried,
                                                           "linear")
    local_t = world[:, :3] if p < 0 else np.einsum("fab,fb->fa", np.linalg.inv(mats[:, p]),
                                                   world)[:, :3]
    tracks[(skeleton.names[hips], "translation")] = Track("translation", times, local_t,
                                                          "linear")
    return Clip(name, skeleton, tracks, duration=max(source_clip.duration, times[-1]),
                loop=source_clip.loop)
