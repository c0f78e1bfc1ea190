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

from scipy.spatial.transform import Rotation

from .calibrate import foot_points, rotations_of, swing, tail_point
from ...model.transforms import unit

__all__ = ["detect_contacts", "runs", "ramp", "pin_offsets", "two_bone_ik", "clean_feet",
           "clean_legs", "solve_legs", "blend_frames", "smooth_max", "HEIGHT_TOL", "SPEED_TOL"]

HEIGHT_TOL = 0.06
SPEED_TOL = 0.5


def runs(mask):
    """(start, stop) index pairs (stop exclusive) of the runs of True in a (F,) bool mask."""
    m = np.r_[False, np.asarray(mask, bool), False].astype(np.int8)
    edges = np.flatnonzero(np.diff(m))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))


def ramp(mask, blend):
    """(F,) float64: 1 where the (F,) bool ``mask`` is True, falling to 0 over ``blend``
    frames either side (``1 - d / (blend + 1)`` at ``d`` frames from the nearest True), the
    weights :func:`pin_offsets` gives a contact's hold."""
    mask = np.asarray(mask, bool)
    if not mask.any():
        return np.zeros(len(mask))
    on = np.flatnonzero(mask)
    f = np.arange(len(mask))
    k = np.clip(np.searchsorted(on, f), 1, len(on) - 1) if len(on) > 1 else np.zeros_like(f)
    d = np.minimum(np.abs(f - on[k]), np.abs(f - on[np.maximum(k - 1, 0)]))
    return np.maximum(0.0, 1.0 - d / (blend + 1))


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


def pin_offsets(points, contact, floor_heights, blend, heights=None):
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
    heights : (F, P) float64, optional
        The height each point should have in each frame of a run (the pin is then held
        horizontally only: its mean x and z, this height); by default the run's mean height.

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
            pin = np.repeat(points[a:b, p].mean(axis=0)[None], n, axis=0)
            if heights is not None:
                pin[:, 1] = heights[:, p]
            pin[:, 1] = np.maximum(pin[:, 1], floor_heights[p])
            offsets[a:b, p] = pin[a:b] - points[a:b, p]
            weights[a:b, p] = 1.0
            for k in range(1, blend + 1):
                w = 1.0 - k / (blend + 1)
                for f, edge in ((a - k, a), (b - 1 + k, b - 1)):
                    if 0 <= f < n and w > weights[f, p]:
                        weights[f, p] = w
                        offsets[f, p] = pin[edge] - points[edge, p]
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


def clean_feet(skeleton, tgt, rot, mats, contact, feet, times, mapped):
    """Hold each contact where it was on average (the ankle moves the foot, the foot turns
    about the ankle to put the toe on its pin while both touch), keep every foot point above
    its rest height, lower the hips where a stretched leg falls short, and solve the legs for
    the new ankles (two-bone IK).

    Returns
    -------
    rot : (F, J, 3, 3) float64
        New model rotations.
    drop : (F,) float64
        How far to lower the hips in each frame.
    """
    rot = rot.copy()
    pts = mats[:, feet][..., :3, 3]
    rest_pts = tgt.mats[feet, :3, 3]
    blend = blend_frames(times)
    offsets, weights = pin_offsets(pts, contact, rest_pts[:, 1], blend)
    goals = {}
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
            # the two pins are means over different frames, so their distance is not quite
            # the foot's length: the toe keeps its pin, the ankle comes as close as it can
            length = np.linalg.norm(toe - ankle, axis=1, keepdims=True)
            goal = goal + wt * (want_toe - length * unit(want_toe - goal) - goal)
            turn = swing(toe - ankle, want_toe - goal)
            for k in skeleton.subtree(foot_j):
                rot[:, k] = turn @ rot[:, k]
        # no foot point (ankle, toe, toe tip) below its rest height
        low = [goal[:, 1], (goal + np.einsum("fab,fb->fa", turn, toe - ankle))[:, 1]]
        rest_low = [rest_pts[ankle_i, 1], rest_pts[toe_i, 1]]
        tip = tail_point(skeleton, mats, toe_j)
        if tip is not None:
            low.append((goal + np.einsum("fab,fb->fa", turn, tip - ankle))[:, 1])
            rest_low.append(tail_point(skeleton, tgt.mats[None], toe_j)[0, 1])
        lift = np.max(np.maximum(0.0, np.array(rest_low)[None] - np.stack(low, axis=1)), axis=1)
        goal[:, 1] += lift
        goals[side] = (ankle, goal)
    legs = [(tgt.slots[f"thigh_{side}"], tgt.slots[f"shin_{side}"], ankle, goal)
            for side, (ankle, goal) in goals.items()]
    return solve_legs(skeleton, tgt, rot, mats, legs, blend, mapped)


def clean_legs(skeleton, tgt, rot, mats, contact, legs, times, mapped, heights=None):
    """:func:`clean_feet` for any number of legs found by structure
    (:class:`rigedit.rigging.retarget.limbs.LegCalibration`): each leg's contact (its foot leaf) is
    held at its mean position by moving the ankle, the foot part moving rigidly with it; no
    point of the foot part goes below the floor (``tgt.floor``); the hips drop where a stretched leg
    falls short; each leg is solved by two-bone IK (upper joint and knee).

    Parameters
    ----------
    contact : (F, len(legs)) bool
        Contact of each leg's foot leaf.
    legs : list of Leg
    heights : (F, len(legs)) float64, optional
        Height of each foot leaf during its contacts (the source's, scaled: a fetlock that
        sinks under the weight keeps doing so); by default each contact's mean height.

    Returns
    -------
    rot : (F, J, 3, 3) float64
    drop : (F,) float64
    """
    rot = rot.copy()
    pts = mats[:, [leg.contact for leg in legs]][..., :3, 3]
    blend = blend_frames(times)
    # the floor, not each point's rest height: a hoof's fetlock sinks while its tip stands
    offsets, weights = pin_offsets(pts, contact, np.full(len(legs), tgt.floor), blend,
                                   heights)
    solve = []
    for i, leg in enumerate(legs):
        ankle = mats[:, leg.ankle, :3, 3]
        goal = ankle + weights[:, i, None] * offsets[:, i]
        # the foot part moves with the ankle: none of its points below the floor
        below = foot_points(skeleton, leg.foot, mats)[..., 1] - ankle[:, 1:2]
        goal[:, 1] += np.maximum(0.0, tgt.floor - below.min(axis=1) - goal[:, 1])
        solve.append((leg.upper, leg.knee, ankle, goal))
    return solve_legs(skeleton, tgt, rot, mats, solve, blend, mapped)


def blend_frames(times):
    """Frames over which a contact's hold fades in and out: 0.1 s, at least 2."""
    dt = float(np.median(np.diff(times))) if len(times) > 1 else 1 / 30
    return max(2, int(round(0.1 / dt)))


def solve_legs(skeleton, tgt, rot, mats, legs, blend, mapped):
    """Lower the hips where a stretched leg cannot reach its goal (by the shortfall, spread
    over the blend window so the body does not jolt), then solve each leg ``(upper, knee,
    ankle (F, 3), goal (F, 3))`` by two-bone IK; joints the map leaves out below the upper
    joints keep their rest pose below the turned ones. Returns ``rot``, ``drop``."""
    n = len(rot)
    drop = np.zeros(n)
    for upper, knee, ankle, goal in legs:
        hip = mats[:, upper, :3, 3]
        reach = 0.999 * (np.linalg.norm(mats[:, knee, :3, 3] - hip, axis=1)
                         + np.linalg.norm(ankle - mats[:, knee, :3, 3], axis=1))
        v = goal - hip
        horiz = np.linalg.norm(v[:, [0, 2]], axis=1)
        # hip height above the goal at which the goal is just in reach
        ok_height = np.sqrt(np.maximum(reach ** 2 - horiz ** 2, 0.0))
        drop = np.maximum(drop, np.maximum(0.0, -v[:, 1] - ok_height))
    if drop.any():
        drop = smooth_max(drop, blend)
    hips_rot = rot[:, tgt.hips]
    normal = hips_rot @ (rotations_of(tgt.mats)[tgt.hips].T @ tgt.left)
    down = np.c_[np.zeros(n), drop, np.zeros(n)]
    for upper, knee, ankle, goal in legs:
        rot[:, upper], rot[:, knee] = two_bone_ik(
            mats[:, upper, :3, 3] - down, mats[:, knee, :3, 3] - down, ankle - down, goal,
            rot[:, upper], rot[:, knee], normal)
    rest_rot = Rotation.from_quat(skeleton.rest_rotation).as_matrix()
    for upper, *_ in legs:
        for j in skeleton.subtree(upper)[1:]:
            if j not in mapped:
                rot[:, j] = rot[:, skeleton.parents[j]] @ rest_rot[j]
    return rot, drop


def smooth_max(x, width):
    """A running maximum over ``2 width + 1`` samples, then a moving average as wide: covers
    every sample's need and ramps in and out."""
    pad = np.pad(x, width, mode="edge")
    windows = np.lib.stride_tricks.sliding_window_view(pad, 2 * width + 1)
    peak = windows.max(axis=1)
    kernel = np.ones(2 * width + 1) / (2 * width + 1)
    return np.maximum(np.convolve(np.pad(peak, width, mode="edge"), kernel, mode="valid"), x)
