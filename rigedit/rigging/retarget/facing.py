"""Facing: which way a figure's hips face, over a whole clip and against its path.

A figure's forward at its calibration decides two things in a retarget (:mod:`.retarget`):
the turn about the vertical that brings the source's facing onto the target's, and the
body frame each mapped bone is aligned in (:mod:`.transfer`), so that the target's hips face
as the source's do. Heel to toe in one pose is a poor forward: mid-stride the feet may point
far off the pelvis (frame 0 of Bandai's dataset-2 run: 90 degrees), and frame 0 of a dash may
face across the way it then runs. So:

- the forward of a pose is the **pelvis'**: horizontal, square to the line from the right
  thigh joint to the left one (a humanoid: which is left comes from the joint names, else
  from the feet), or the calibration's forward carried by the hips' rotation (any other
  skeleton);
- the forward of a **clip** is the rest pose's where the rest stands (the calibration is the
  rest: its forward is the rig's convention), else the mean over all frames of the hips'
  forward (a unit-vector mean: a clip that faces one way for most of its frames faces that
  way, whatever frame 0 does).

The hips' heading relative to their path (:func:`relative_heading`) is the measure: the angle
from the direction the hips travel (over :data:`PATH_WINDOW` seconds) to the way they face,
in frames where they travel at least :data:`MIN_SPEED` leg lengths a second.
"""
from __future__ import annotations

import numpy as np

from .calibrate import rotations_of
from ...model.transforms import unit

__all__ = ["hips_forward", "pose_forward", "clip_forward", "facing_doubt", "heading_degrees",
           "relative_heading", "heading_offsets", "face_by_hips", "PATH_WINDOW", "MIN_SPEED",
           "MIN_AGREEMENT"]

#: Seconds over which the hips' direction of travel is measured (a stride's sway averages out).
PATH_WINDOW = 0.5
#: Frames where the hips travel slower than this (leg lengths per second) have no path.
MIN_SPEED = 0.3
#: A clip whose hips' forward, averaged over its frames as unit vectors, is shorter than
#: this faces no one way (a spin).
MIN_AGREEMENT = 0.5

_UP = np.array([0.0, 1.0, 0.0])


def _horizontal(v):
    v = np.array(v, dtype=np.float64)
    v[..., 1] = 0.0
    return unit(v)


def pose_forward(calib, mats):
    """(F, 3) unit horizontal forward of the pelvis in each pose ``mats`` (F, J, 4, 4) of
    ``calib``'s skeleton (see the module notes); zero where it is undefined (thighs one
    above the other)."""
    mats = np.asarray(mats, dtype=np.float64)
    slots = getattr(calib, "slots", None)
    if slots is not None and "thigh_L" in slots and "thigh_R" in slots:
        # left is up x forward: forward is (thigh_R -> thigh_L) x up. Which thigh is left
        # comes from the names, else from the feet (name_map.find_slots).
        lateral = mats[:, slots["thigh_L"], :3, 3] - mats[:, slots["thigh_R"], :3, 3]
        return _horizontal(np.cross(lateral, _UP))
    return hips_forward(calib, mats)


def hips_forward(calib, mats):
    """(F, 3) ``calib.forward`` carried by the hips joint's rotation into each pose
    ``mats`` (F, J, 4, 4), made horizontal."""
    h = calib.hips
    rel = rotations_of(np.asarray(mats)[:, h]) @ rotations_of(calib.mats[h]).T
    return _horizontal(rel @ calib.forward)


def face_by_hips(calib):
    """Set a humanoid calibration's ``forward`` and ``left`` from its pelvis when the pose is
    not the rest (frame 0 of a clip, mid-stride perhaps); the rest's feet are kept, as a
    rest stands square. Returns whether they changed."""
    if calib.source == "rest" or calib.kind != "humanoid":
        return False
    fwd = pose_forward(calib, calib.mats[None])[0]
    if not np.any(fwd):
        return False
    calib.forward = fwd
    calib.left = np.cross(_UP, fwd)
    return True


def clip_forward(calib, mats):
    """(3,) unit horizontal forward of a clip (see the module notes): ``calib.forward`` when
    ``calib`` is the rest pose, else the mean of :func:`pose_forward` over ``mats``
    (F, J, 4, 4)."""
    if calib.source == "rest" or not len(mats):
        return _horizontal(calib.forward)
    mean = pose_forward(calib, mats).mean(axis=0)
    return _horizontal(mean) if np.linalg.norm(mean) > 1e-6 else _horizontal(calib.forward)


def facing_doubt(calib, mats, times):
    """One line saying why the facing turn of a clip may be wrong, or "" when it is sure.

    Doubtful: a clip whose hips face every way (the mean of their forward over the frames is
    shorter than :data:`MIN_AGREEMENT`: a spin), and a clip whose hips face away from their
    path in most travelling frames (a backward walk, or left and right swapped). A rest that
    stands is never doubted (its forward is the rig's). Where a clip faces halfway between
    two quarter turns of the target's forward the turn is a toss-up too, but either keeps
    the hips' heading relative to the path, so it is not reported.
    """
    if calib.source == "rest" or not len(mats):
        return ""
    forwards = pose_forward(calib, mats)
    agree = float(np.linalg.norm(forwards.mean(axis=0)))
    if agree < MIN_AGREEMENT:
        return (f"the source's hips face every way over the clip (their mean forward is "
                f"{agree:.2f} long): the facing turn is a guess")
    rel = relative_heading(calib, mats, times)
    moving = np.isfinite(rel)
    if moving.sum() >= 0.5 * len(rel) and np.mean(np.abs(rel[moving]) > 135.0) > 0.5:
        return ("the source's hips face away from their path in most frames (a backward "
                "walk, or its left and right swapped)")
    return ""


def heading_degrees(v):
    """Heading of horizontal direction(s) ``v`` (..., 3), degrees about +Y from +Z."""
    v = np.asarray(v, dtype=np.float64)
    return np.degrees(np.arctan2(v[..., 0], v[..., 2]))


def _wrap(deg):
    return (np.asarray(deg) + 180.0) % 360.0 - 180.0


def relative_heading(calib, mats, times, leg=None):
    """Degrees from the hips' direction of travel to their forward, per frame.

    Parameters
    ----------
    calib : Calibration or LegCalibration
    mats : (F, J, 4, 4) float
        Model matrices of the clip on ``calib``'s skeleton.
    times : (F,) float
    leg : float, optional
        Leg length for the speed threshold (``calib.hip_height`` by default).

    Returns
    -------
    degrees : (F,) float64
        In [-180, 180); NaN where the hips travel slower than :data:`MIN_SPEED`.
    """
    times = np.asarray(times, dtype=np.float64)
    hips = np.asarray(mats)[:, calib.hips, :3, 3]
    out = np.full(len(times), np.nan)
    if len(times) < 2:
        return out
    half = PATH_WINDOW / 2
    lo = np.searchsorted(times, times - half)
    hi = np.minimum(np.searchsorted(times, times + half, side="right") - 1, len(times) - 1)
    dt = times[hi] - times[lo]
    step = (hips[hi] - hips[lo]) * [1.0, 0.0, 1.0]
    speed = np.linalg.norm(step, axis=1) / np.where(dt > 0, dt, np.inf)
    moving = speed >= MIN_SPEED * (leg or calib.hip_height)
    rel = _wrap(heading_degrees(pose_forward(calib, mats)) - heading_degrees(step))
    out[moving] = rel[moving]
    return out


def heading_offsets(result):
    """Per frame, the target's hips' heading relative to its path minus the source's
    (degrees, NaN where either is not travelling): zero when the target faces its path as
    the source does. ``result`` is a :class:`rigedit.rigging.retarget.pipeline.RetargetResult`."""
    s = relative_heading(result.source_calibration, result.source_mats, result.times)
    t = relative_heading(result.target_calibration, result.mats, result.times,
                         leg=result.target_calibration.hip_height)
    return _wrap(t - s)
