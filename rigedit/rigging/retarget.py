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
from .contacts import detect_contacts, pin_offsets, two_bone_ik
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
    src_feet = [src.slots[k] for k in ("foot_L", "foot_R")] + [
        src.slots.get(k, src.slots[f]) for k, f in (("toe_L", "foot_L"), ("toe_R", "foot_R"))]
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
    _distribute(tsk, tgt, rot, inverse)
    scale = tgt.hip_height / src.hip_height
    hips_s = smats[:, inverse[tgt.slots["hips"]], :3, 3]
    hips_t = hips_s * scale
    # the thigh joints go where the source's go, scaled: the pelvis depth is each one's own
    hips_t[:, 1] = tgt.joint_floor + (hips_s[:, 1] - s_floor - src.hip_offset) * scale \
        + tgt.hip_offset
    raw = _assemble(tsk, rot, tgt.slots["hips"], hips_t)
    tgt_feet = [tgt.slots[k] for k in ("foot_L", "foot_R")] + [
        tgt.slots.get(k, tgt.slots[f]) for k, f in (("toe_L", "foot_L"), ("toe_R", "foot_R"))]
    mats = raw
    if clean_feet:
        rot = _clean_feet(tsk, tgt, rot, raw, contact, tgt_feet, times, inverse)
        mats = _assemble(tsk, rot, tgt.slots["hips"], hips_t)
    clip = _to_clip(tsk, mats, rot, times, name or source_clip.name, source_clip,
                    tgt.slots["hips"])
    return RetargetResult(clip, dict(map), src, tgt, facing, scale, times, smats, raw, mats,
                          contact, s_floor, pairs)


def _distribute(skeleton, tgt, rot, mapped):
    """Share the bend between two mapped spine or neck joints with the unmapped joints
    between them (a source spine of 2 joints onto a target of 3), in place.

    With ``a`` and ``b`` consecutive mapped joints of the chain and ``k`` unmapped joints
    between, ``D`` is ``b``'s turn beyond its calibration relation to ``a``; the ``i``-th joint
    between takes ``D^(i/(k+1))`` (so the bend is spread and ``b`` keeps its orientation).
    Unless ``a`` is the hips (whose orientation is the whole body's), one swing at ``a`` then
    re-aims ``a -> b`` where it pointed.
    """
    cal = rotations_of(tgt.mats)
    for chain in (tgt.chains["spine"], [tgt.slots["chest"]] + tgt.chains["neck"]):
        marks = [i for i, j in enumerate(chain) if j in mapped]
        for i0, i1 in zip(marks[:-1], marks[1:]):
            a, b, run = chain[i0], chain[i1], chain[i0 + 1:i1]
            if not run:
                continue
            rigid = rot[:, a] @ (cal[a].T @ cal[b])
            delta = Rotation.from_matrix(rot[:, b] @ np.swapaxes(rigid, -1, -2)).as_rotvec()
            before = _chain_vector(skeleton, rot, run + [b])
            n = len(run) + 1
            for k, j in enumerate(run, 1):
                step = Rotation.from_rotvec(delta * (k / n)).as_matrix()
                rot[:, j] = step @ rot[:, a] @ (cal[a].T @ cal[j])
            if a != tgt.slots["hips"]:
                turn = swing(_chain_vector(skeleton, rot, run + [b]), before)
                for j in [a] + run:
                    rot[:, j] = turn @ rot[:, j]


def _chain_vector(skeleton, rot, joints):
    """(F, 3) model vector from the parent of ``joints[0]`` to ``joints[-1]`` through each
    joint's rest offset, each turned by its parent's model rotation."""
    return sum(rot[:, skeleton.parents[j]] @ (skeleton.rest_translation[j]
                                             * skeleton.rest_scale[skeleton.parents[j]])
               for j in joints)


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


def _clean_feet(skeleton, tgt, rot, mats, contact, feet, times, mapped):
    """Hold each contact where it was on average (the ankle moves the foot, the foot turns
    about the ankle to put the toe on its pin while both touch), keep every foot point above
    its rest height, and solve the legs for the new ankles (two-bone IK)."""
    rot = rot.copy()
    pts = mats[:, feet][..., :3, 3]
    rest_pts = tgt.mats[feet, :3, 3]
    dt = float(np.median(np.diff(times))) if len(times) > 1 else 1 / 30
    offsets, weights = pin_offsets(pts, contact, rest_pts[:, 1], max(2, int(round(0.1 / dt))))
    hips_rot = rot[:, tgt.slots["hips"]]
    for side, (ankle_i, toe_i) in (("L", (0, 2)), ("R", (1, 3))):
        wa, wt = weights[:, ankle_i, None], weights[:, toe_i, None]
        da, dtoe = offsets[:, ankle_i], offsets[:, toe_i]
        delta = wa * da + (1 - wa) * wt * dtoe
        ankle, toe = pts[:, ankle_i], pts[:, toe_i]
        goal = ankle + delta
        foot_j, toe_j = feet[ankle_i], feet[toe_i]
        turn = np.broadcast_to(np.eye(3), (len(times), 3, 3))
        if toe_j != foot_j:
            want_toe = toe + delta + wt * (dtoe - delta)
            turn = swing(toe - ankle, want_toe - goal)
            for k in skeleton.subtree(foot_j):
                rot[:, k] = turn @ rot[:, k]
        # no foot point (ankle, toe, toe tip) below its rest height
        low = [goal[:, 1], (goal + np.einsum("fab,fb->fa", turn, toe - ankle))[:, 1]]
        rest_low = [rest_pts[ankle_i, 1], rest_pts[toe_i, 1]]
        tip = _tail_point(skeleton, mats, toe_j)
        if tip is not None:
            low.append((goal + np.einsum("fab,fb->fa", turn, tip - ankle))[:, 1])
            rest_low.append(_tail_point(skeleton, tgt.mats[None], toe_j)[0, 1])
        lift = np.max(np.maximum(0.0, np.array(rest_low)[None] - np.stack(low, axis=1)), axis=1)
        goal[:, 1] += lift
        th, sh = tgt.slots[f"thigh_{side}"], tgt.slots[f"shin_{side}"]
        normal = hips_rot @ (rotations_of(tgt.mats)[tgt.slots["hips"]].T @ tgt.left)
        rot[:, th], rot[:, sh] = two_bone_ik(
            mats[:, th, :3, 3], mats[:, sh, :3, 3], ankle, goal, rot[:, th], rot[:, sh],
            normal)
    # joints the map leaves out in the legs keep their rest pose below the turned ones
    rest_rot = Rotation.from_quat(skeleton.rest_rotation).as_matrix()
    for side in "LR":
        for j in skeleton.subtree(tgt.slots[f"thigh_{side}"])[1:]:
            if j not in mapped:
                rot[:, j] = rot[:, skeleton.parents[j]] @ rest_rot[j]
    return rot


def _tail_point(skeleton, mats, j):
    """(F, 3) model position of joint ``j``'s tail, or None when it has none."""
    if not np.all(np.isfinite(skeleton.tails[j])):
        return None
    local = skeleton.inverse_bind_matrices[j] @ np.r_[skeleton.tails[j], 1.0]
    return (mats[:, j] @ local)[:, :3]


def _to_clip(skeleton, mats, rot, times, name, source_clip, hips):
    """Local keys from model matrices: a rotation track per joint whose rotation moves, a
    translation track for the hips."""
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
    local_t = world[:, :3] if p < 0 else np.einsum("fab,fb->fa", np.linalg.inv(mats[:, p]),
                                                   world)[:, :3]
    tracks[(skeleton.names[hips], "translation")] = Track("translation", times, local_t,
                                                          "linear")
    return Clip(name, skeleton, tracks, duration=max(source_clip.duration, times[-1]),
                loop=source_clip.loop)
