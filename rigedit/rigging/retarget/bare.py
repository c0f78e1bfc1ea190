"""Retargeting between two skeletons that share joint names but stand on no legs the other
calibrations can find: a rig without legs (a tentacle, Khronos' RiggedSimple), or a game rig
whose feet are IK targets under the root (three.js' RobotExpressive, Quaternius' horse: the
leg chains end at the knee, the foot is a root-level joint moved by translation).

Nothing here knows a floor, a facing or a foot: each mapped joint turns in model space as
its source joint turns from its rest (``T(t) = S(t) · S_r⁻¹ · T_r``, the rests' model
rotations), and each joint the source clip translates moves from its rest by the source's
local offset, scaled by the ratio of the figures' sizes (the extent of the joints below the
first branch: carrier roots left out). Two rigs of one family (a character onto itself, or
onto a copy in other proportions) come back exactly; rigs whose rests differ in their bone
rolls turn by the rolls' difference, which is why the humanoid and leg calibrations are
tried first and this only when neither finds legs. The retarget warns that it did so.
"""
from __future__ import annotations

import warnings

import numpy as np
from scipy.spatial.transform import Rotation

from ...animation.clip import Clip, Track
from ...model.transforms import compose_trs
from .calibrate import calibrate, model_stack, rotations_of
from .limbs import LegCalibration
from .name_map import name_pairs

__all__ = ["BareCalibration", "bare_result", "MIN_SHARE"]

#: Share of the target's joints equal names must reach for a retarget without legs.
MIN_SHARE = 0.5


class BareCalibration:
    """A skeleton's rest and size, for :func:`bare_result`.

    Attributes
    ----------
    skeleton : Skeleton
    mats : (J, 4, 4) float64
        Rest model matrices.
    points : (J, 3) float64
    size : float
        Largest extent of the joints from the first branching joint down.
    hips : int
        The first root joint (what carries the figure).
    source : str
        ``"rest"``.
    """

    kind = "bare"
    groups = ("bones",)
    legs, contacts, feet = (), (), ()

    def __init__(self, skeleton, what):
        self.skeleton, self.source = skeleton, "rest"
        self.mats = skeleton.forward(skeleton.rest_local_matrices())
        self.points = self.mats[:, :3, 3]
        j = int(np.flatnonzero(skeleton.parents < 0)[0])
        self.hips = j
        while len(skeleton.children(j)) == 1:
            j = int(skeleton.children(j)[0])
        body = skeleton.subtree(j)
        self.size = float(np.ptp(self.points[body], axis=0).max()) if len(body) > 1 else 1.0
        self.size = self.size or 1.0
        self.floor = self.joint_floor = float(self.points[:, 1].min())
        self.hip_height = self.size

    def group(self, j):
        """Every joint is in the one group ``"bones"``."""
        return "bones"

    def foot_points(self, mats):
        """No feet: (F, 0, 3)."""
        return np.zeros((len(mats), 0, 3))


def bare_result(source_rig, source_clip, target_rig, mapping, name, times, source_what,
                target_what, reason):
    """Retarget by equal names (or ``mapping``) without legs, floor or facing.

    Parameters
    ----------
    source_rig, target_rig : Rig
    source_clip : Clip
    mapping : dict[str, str] or None
        Source joint -> target joint; equal names (:func:`name_pairs`) when None.
    name : str or None
    times : (F,) float64
        The sample times.
    source_what, target_what : str
        How to name the two in messages.
    reason : str
        Why the other calibrations did not apply (for the warning).

    Returns
    -------
    fields : dict or None
        The :class:`rigedit.rigging.retarget.pipeline.RetargetResult` fields; None when either
        skeleton has legs (:class:`LegCalibration` finds them), or the map (which must name
        joints both have) reaches neither the target's root nor :data:`MIN_SHARE` of its
        joints: then ``reason`` stands as the error.
    """
    ssk, tsk = source_rig.skeleton, target_rig.skeleton
    if _has_legs(ssk, [source_clip]) or _has_legs(tsk, list(target_rig.clips.values())):
        return None  # a figure with legs is no rig of a legless one's family
    if mapping is None:
        mapping = name_pairs(ssk, tsk)
    src, tgt = BareCalibration(ssk, source_what), BareCalibration(tsk, target_what)
    if not all(s in ssk.index and t in tsk.index for s, t in mapping.items()):
        return None
    inverse = {tsk.index[t]: ssk.index[s] for s, t in mapping.items()}
    if tgt.hips not in inverse or len(inverse) < MIN_SHARE * len(tsk):
        return None
    warnings.warn(f"{reason}; retargeted by joint names ({len(inverse)} of {len(tsk)} "
                  f"joints) without a floor, facing or foot clean-up")
    scale = tgt.size / src.size
    smats = model_stack(ssk, source_clip, times)
    quats = _turned_as_source(src, tgt, inverse, smats)
    trans, moved = _moved_as_source(ssk, tsk, source_clip, inverse, smats, scale)
    n_frames, nj = len(times), len(tsk)
    mats = np.empty((n_frames, nj, 4, 4))
    for f in range(n_frames):
        tsk.forward(compose_trs(trans[f], quats[f], tsk.rest_scale), out=mats[f])
    tracks = {}
    for j in range(nj):
        if j in inverse:
            tracks[(tsk.names[j], "rotation")] = Track("rotation", times, quats[:, j], "slerp")
        if j in moved:
            tracks[(tsk.names[j], "translation")] = Track("translation", times, trans[:, j],
                                                          "linear")
    clip = Clip(name or source_clip.name, tsk, tracks,
                duration=max(source_clip.duration, times[-1]), loop=source_clip.loop)
    pairs = []
    for j, s in inverse.items():
        kids = [c for c in tsk.children(j) if c in inverse]
        if kids:
            pairs.append((j, (int(kids[0]), np.zeros(3)), s, (inverse[int(kids[0])],
                                                               np.zeros(3))))
    return dict(clip=clip, mapping=dict(mapping), source_calibration=src,
                target_calibration=tgt, facing_degrees=0.0, scale=scale, times=times,
                source_mats=smats, raw_mats=mats, mats=mats,
                contact=np.zeros((n_frames, 0), bool), source_floor=src.floor, pairs=pairs)


def _has_legs(skeleton, clips):
    """Whether :class:`LegCalibration` finds legs on ``skeleton`` (in its rest or a frame
    of ``clips``)."""
    try:
        calibrate(skeleton, clips, "", LegCalibration)
        return True
    except ValueError:
        return False


def _turned_as_source(src, tgt, inverse, smats):
    """(F, J, 4) local rotations (quaternions) of the target: each mapped joint turned in
    model space as its source joint turns from its rest, every other joint keeping its rest
    relation to its parent.

    Parameters
    ----------
    src, tgt : BareCalibration
    inverse : dict[int, int]
        Target joint -> source joint.
    smats : (F, Js, 4, 4) float64
        The source's model matrices over the clip.
    """
    tsk = tgt.skeleton
    s_rot, s_rest = rotations_of(smats), rotations_of(src.mats)
    t_rest = rotations_of(tgt.mats)
    n_frames, nj = len(smats), len(tsk)
    rot = np.empty((n_frames, nj, 3, 3))
    for j in range(nj):
        p = tsk.parents[j]
        if j in inverse:
            s = inverse[j]
            rot[:, j] = s_rot[:, s] @ (s_rest[s].T @ t_rest[j])
        else:  # keeps its rest relation to its parent
            rel = t_rest[j] if p < 0 else t_rest[p].T @ t_rest[j]
            rot[:, j] = rel if p < 0 else rot[:, p] @ rel
    local_rot = np.array([rot[:, j] if tsk.parents[j] < 0 else
                          np.swapaxes(rot[:, tsk.parents[j]], -1, -2) @ rot[:, j]
                          for j in range(nj)]).swapaxes(0, 1)
    return Rotation.from_matrix(local_rot.reshape(-1, 3, 3)).as_quat().reshape(n_frames, nj, 4)


def _moved_as_source(ssk, tsk, source_clip, inverse, smats, scale):
    """``(trans, moved)``: (F, J, 3) local translations of the target, each joint whose
    source joint the clip translates moved from its rest by the source's local offset times
    ``scale``, the others at rest; and those joints, {target joint: source joint}."""
    trans = np.broadcast_to(tsk.rest_translation, (len(smats), len(tsk), 3)).copy()
    moved = {}
    for (joint, channel) in source_clip.tracks:
        s = ssk.index[joint]
        t = next((tj for tj, sj in inverse.items() if sj == s), None)
        if channel == "translation" and t is not None:
            moved[t] = s
    for t, s in moved.items():
        local = _local_translations(ssk, smats, s)
        trans[:, t] = tsk.rest_translation[t] + (local - ssk.rest_translation[s]) * scale
    return trans, moved


def _local_translations(skeleton, mats, j):
    """(F, 3) joint ``j``'s translation in its parent's frame (its rest scale's units)."""
    p = skeleton.parents[j]
    if p < 0:
        return mats[:, j, :3, 3]
    inv = np.linalg.inv(mats[:, p])
    return np.einsum("fab,fb->fa", inv, np.c_[mats[:, j, :3, 3], np.ones(len(mats))])[:, :3]
