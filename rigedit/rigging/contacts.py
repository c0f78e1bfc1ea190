"""Foot contacts: detection in the source motion, and holding the target's feet there.

A foot point (ankle or toe joint) is in contact while it is near its standing height and
slow: below ``height_tol * L`` above its height in the calibration pose and moving slower than
``speed_tol * L`` per second horizontally, with ``L`` the figure's hip height (so the same
thresholds serve a child and a giant, centimetres and metres). Runs shorter than
``min_time`` are dropped. On the target each run pins the point at its mean position there;
the ankle goal is moved by the pin's offset (blended in and out over ``blend_time``), raised
so that no foot point goes below its rest height, and the leg (thigh, shin) is solved by
analytic two-bone IK in the plane of its current bend, so the knee keeps pointing where it
pointed and the foot keeps its orientation.
"""
from __future__ import annotations

import numpy as np

from .calibrate import swing, unit

__all__ = ["detect_contacts", "runs", "pin_offsets", "two_bone_ik", "HEIGHT_TOL", "SPEED_TOL"]

HEIGHT_TOL = 0.06
SPEED_TOL = 0.5


def runs(mask):
    """(start, stop) index pairs (stop exclusive) of the runs of True in a (F,) bool mask."""
    m = np.r_[False, np.asarray(mask, bool), False].astype(np.int8)
    edges = np.flatnonzero(np.diff(m))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))


def detect_contacts(points, rest_heights, times, leg_length, height_tol=HEIGHT_TOL,
                    speed_tol=SPEED_TOL, min_time=0.05):
    """Contact masks of foot points.

    Parameters
    ----------
    points : (F, P, 3) float64
        Model positions of P foot points over F frames (Y up), floor at y = 0.
    rest_heights : (P,) float64
        Each point's height above the floor when standing.
    times : (F,) float64
    leg_length : float
        The figure's hip height; thresholds scale with it.

    Returns
    -------
    contact : (F, P) bool
    """
    times = np.asarray(times, dtype=np.float64)
    if len(times) < 2:
        return np.zeros(points.shape[:2], dtype=bool)
    flat = points[..., [0, 2]]
    speed = np.linalg.norm(np.gradient(flat, times, axis=0), axis=-1)
    low = points[..., 1] - rest_heights[None] < height_tol * leg_length
    contact = low & (speed < speed_tol * leg_length)
    dt = float(np.median(np.diff(times)))
    shortest = max(2, int(round(min_time / dt)))
    for p in range(contact.shape[1]):
        for a, b in runs(contact[:, p]):
            if b - a < shortest:
                contact[a:b, p] = False
    return contact


def pin_offsets(points, contact, floor_heights, blend):
    """Per-frame offsets that hold each contact run's point at its mean position.

    Parameters
    ----------
    points : (F, P, 3) float64
        Target foot points before clean-up.
    contact : (F, P) bool
    floor_heights : (P,) float64
        No pin lower than these.
    blend : int
        Frames over which an offset fades in before a run and out after it.

    Returns
    -------
    offsets : (F, P, 3) float64
    weights : (F, P) float64
        1 inside runs, ramping to 0 over ``blend`` frames outside.
    """
    n, npts = contact.shape
    offsets = np.zeros((n, npts, 3))
    weights = np.zeros((n, npts))
    for p in range(npts):
        for a, b in runs(contact[:, p]):
            pin = points[a:b, p].mean(axis=0)
            pin[1] = max(pin[1], floor_heights[p])
            offsets[a:b, p] = pin - points[a:b, p]
            weights[a:b, p] = 1.0
            for k in range(1, blend + 1):
                w = 1.0 - k / (blend + 1)
                for f, edge in ((a - k, a), (b - 1 + k, b - 1)):
                    if 0 <= f < n and w > weights[f, p]:
                        weights[f, p] = w
                        offsets[f, p] = pin - points[edge, p]
    return offsets, weights


def two_bone_ik(hip, knee, ankle, goal, thigh_rot, shin_rot, fallback_normal):
    """Analytic two-bone IK, batched over frames.

    Parameters
    ----------
    hip, knee, ankle, goal : (F, 3) float64
        Model positions; the hip stays.
    thigh_rot, shin_rot : (F, 3, 3) float64
        Model rotations of the thigh and shin joints.
    fallback_normal : (F, 3) float64
        Bend-plane normal used where the leg is straight.

    Returns
    -------
    thigh_rot, shin_rot : (F, 3, 3) float64
        New model rotations: the ankle reaches the goal where the leg is long enough (else
        the leg points at it, straight); the knee stays in the plane of its current bend.
    """
    a = np.linalg.norm(knee - hip, axis=-1)
    b = np.linalg.norm(ankle - knee, axis=-1)
    to_goal = goal - hip
    d = np.clip(np.linalg.norm(to_goal, axis=-1), np.abs(a - b) + 1e-9, (a + b) * (1 - 1e-6))
    e = unit(to_goal)
    cos_a = np.clip((a ** 2 + d ** 2 - b ** 2) / (2 * a * d), -1.0, 1.0)
    k_off = knee - hip
    pole = k_off - e * np.sum(k_off * e, axis=-1, keepdims=True)
    bad = np.linalg.norm(pole, axis=-1) < 1e-6 * a
    pole[bad] = np.cross(fallback_normal[bad], e[bad])
    pole = unit(pole)
    new_knee = hip + a[:, None] * (cos_a[:, None] * e + np.sqrt(1 - cos_a ** 2)[:, None] * pole)
    new_ankle = hip + d[:, None] * e
    thigh = swing(k_off, new_knee - hip) @ thigh_rot
    shin = swing(ankle - knee, new_ankle - new_knee) @ shin_rot
    return thigh, shin
