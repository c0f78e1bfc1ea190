"""Calibration poses, body frames and batched rotation helpers for retargeting."""
from __future__ import annotations

import numpy as np

from ...model.transforms import compose_trs, unit
from .name_map import find_slots

__all__ = ["Calibration", "calibrate", "model_stack", "swing", "rotations_of",
           "foot_points", "tail_point", "ancestors", "HUMANOID_GROUPS"]

#: Groups of bones reported by :func:`rigedit.rigging.retarget.measure.direction_errors` for humanoids:
#: "feet" (foot and toe bones) apart, as their pitch is transferred relative to each figure's
#: flat foot, not copied (see :mod:`.retarget`), so they differ by design; "fingers": the
#: joints below the hands, mapped when both skeletons name them.
HUMANOID_GROUPS = ("arms", "legs", "spine", "head", "feet", "fingers")


def swing(a, b):
    """Smallest rotations taking directions ``a`` to ``b``.

    Parameters
    ----------
    a, b : (..., 3) float64
        Any lengths; a zero vector on either side gives the identity.

    Returns
    -------
    R : (..., 3, 3) float64
    """
    a, b = unit(a), unit(b)
    shape = np.broadcast_shapes(a.shape, b.shape)
    a, b = np.broadcast_to(a, shape), np.broadcast_to(b, shape)
    v = np.cross(a, b)
    c = np.sum(a * b, axis=-1)
    # Nearly opposite: half a turn about an axis perpendicular to a (Rodrigues fails there).
    opposite = c < -1 + 1e-9
    if np.any(opposite):
        perp = np.cross(a, [1.0, 0.0, 0.0])
        perp = np.where(np.linalg.norm(perp, axis=-1, keepdims=True) < 1e-6,
                        np.cross(a, [0.0, 1.0, 0.0]), perp)
        perp = unit(perp)
        v = np.where(opposite[..., None], perp, v)
    k = np.zeros(shape[:-1] + (3, 3))
    k[..., 0, 1], k[..., 0, 2], k[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    k[..., 1, 0], k[..., 2, 0], k[..., 2, 1] = v[..., 2], -v[..., 1], v[..., 0]
    factor = np.where(opposite, 0.0, 1.0 / np.maximum(1.0 + c, 1e-12))[..., None, None]
    eye = np.broadcast_to(np.eye(3), k.shape)
    rot = eye + k + (k @ k) * factor
    # half turn about the unit axis p: 2 p p^T - I
    half = 2 * v[..., :, None] * v[..., None, :] - eye
    rot = np.where(opposite[..., None, None], half, rot)
    degenerate = (np.linalg.norm(a, axis=-1) == 0) | (np.linalg.norm(b, axis=-1) == 0)
    return np.where(degenerate[..., None, None], eye, rot)


def rotations_of(mats):
    """(..., 3, 3) rotation parts of (..., 4, 4) matrices, any scale divided out."""
    lin = mats[..., :3, :3]
    return lin / np.linalg.norm(lin, axis=-2, keepdims=True)


def model_stack(skeleton, clip, times):
    """Model matrices of a clip at each time, all frames at once: a track keyed at exactly
    the sample times gives its keys (a BVH's or a baked clip's, the usual case), any other is
    sampled; then one batched product per tree depth over every frame.

    Returns
    -------
    mats : (F, J, 4, 4) float64
    """
    n_frames, nj = len(times), len(skeleton)
    local_t = np.array([clip.local_time(t) for t in times])
    channels = {"translation": np.broadcast_to(skeleton.rest_translation, (n_frames, nj, 3)),
                "rotation": np.broadcast_to(skeleton.rest_rotation, (n_frames, nj, 4)),
                "scale": np.broadcast_to(skeleton.rest_scale, (n_frames, nj, 3))}
    channels = {k: v.copy() for k, v in channels.items()}
    for (joint, channel), track in clip.tracks.items():
        j = skeleton.index[joint]
        if len(track.times) == n_frames and np.allclose(track.times, local_t, rtol=0.0,
                                                        atol=1e-9):
            values = track.values
            if channel == "rotation":  # a cubic spline's keys may be kept as given
                values = values / np.linalg.norm(values, axis=1, keepdims=True)
        else:
            values = np.array([track.sample(t) for t in local_t])
        channels[channel][:, j] = values
    local = compose_trs(channels["translation"].reshape(-1, 3),
                        channels["rotation"].reshape(-1, 4),
                        channels["scale"].reshape(-1, 3)).reshape(n_frames, nj, 4, 4)
    out = np.empty_like(local)
    out[:, skeleton.levels[0]] = local[:, skeleton.levels[0]]
    for idx in skeleton.levels[1:]:
        out[:, idx] = out[:, skeleton.parents[idx]] @ local[:, idx]
    return out


class Calibration:
    """A standing pose of a skeleton with its humanoid slots and body frame.

    Attributes
    ----------
    mats : (J, 4, 4) float64
        Model matrices of the pose.
    points : (J, 3) float64
    slots, chains, forward
        See :func:`rigedit.rigging.retarget.name_map.find_slots`.
    source : str
        ``"rest"`` or ``"frame 0 of <clip>"``.
    up, left : (3,) float64
        Unit body axes: hips to chest, and from the right limbs to the left ones.
    contacts : list of 4 int
        Left and right ankle, then left and right toe joints (the ankle where a toe is
        missing): the foot contact points.
    floor : float
        Lowest foot point (feet, toes and their tails) in the pose, model y.
    joint_floor : float
        Lowest foot or toe joint in the pose (tails left out, as not every format has them).
    hip_height : float
        The height of the thigh joints of the figure standing straight: thigh, shin and
        ankle height (the leg length).
    hip_offset : float
        Height of the hips joint above the thigh joints in the pose.
    """

    kind = "humanoid"
    groups = HUMANOID_GROUPS

    def __init__(self, skeleton, mats, source, what):
        self.skeleton, self.mats, self.source = skeleton, mats, source
        self.points = mats[:, :3, 3]
        self.slots, self.chains, self.forward = find_slots(skeleton, self.points, what)
        p, s = self.points, self.slots
        self.up = unit(p[s["chest"]] - p[s["hips"]])
        left = (p[s["thigh_L"]] - p[s["thigh_R"]]) + (p[s["upper_arm_L"]] - p[s["upper_arm_R"]])
        self.left = unit(left - self.up * np.dot(left, self.up))
        self.feet = [s[k] for k in ("foot_L", "foot_R", "toe_L", "toe_R") if k in s]
        # the contact points: left/right ankle, then left/right toe (the ankle without a toe)
        self.contacts = [s["foot_L"], s["foot_R"], s.get("toe_L", s["foot_L"]),
                         s.get("toe_R", s["foot_R"])]
        self.floor = float(self.foot_points(mats[None])[0, :, 1].min())
        self.joint_floor = float(p[self.feet, 1].min())
        # Leg length standing: thigh, shin and the lower ankle's height, so a rest with
        # splayed or bent legs (CMU's) does not shrink it; the hips joint sits hip_offset
        # above the thigh joints (a deep pelvis is not leg).
        legs = [np.linalg.norm(p[s[f"shin_{k}"]] - p[s[f"thigh_{k}"]])
                + np.linalg.norm(p[s[f"foot_{k}"]] - p[s[f"shin_{k}"]]) for k in "LR"]
        ankle = min(p[s["foot_L"], 1], p[s["foot_R"], 1]) - self.joint_floor
        self.hip_height = float(np.mean(legs) + ankle)
        self.hip_offset = float(p[s["hips"], 1] - np.mean([p[s["thigh_L"], 1],
                                                           p[s["thigh_R"], 1]]))

    @property
    def hips(self):
        """The hips joint (index)."""
        return self.slots["hips"]

    def foot_points(self, mats):
        """(F, P, 3) model positions of the foot and toe joints (and their tails)."""
        return foot_points(self.skeleton, self.feet, mats)

    def group(self, j):
        """The measure group of joint ``j`` (one of :data:`HUMANOID_GROUPS`), or None."""
        slot = {v: k for k, v in self.slots.items()}.get(j)
        if slot is None:
            hands = {self.slots[f"hand_{k}"] for k in "LR"}
            return "spine" if j in self.chains["spine"] else \
                "head" if j in self.chains["neck"] else \
                "fingers" if hands & set(ancestors(self.skeleton, j)) else None
        if slot.startswith(("clavicle", "upper_arm", "forearm", "hand")):
            return "arms"
        if slot.startswith(("thigh", "shin")):
            return "legs"
        if slot.startswith(("foot", "toe")):
            return "feet"
        return "head" if slot in ("neck", "head") else "spine"


def ancestors(skeleton, j):
    """Joint ``j`` and its ancestors up to the root, in that order."""
    out = []
    while j >= 0:
        out.append(int(j))
        j = skeleton.parents[j]
    return out


def tail_point(skeleton, mats, j):
    """(F, 3) model position of joint ``j``'s tail in the poses ``mats`` (F, J, 4, 4), or
    None when it has none."""
    if not np.all(np.isfinite(skeleton.tails[j])):
        return None
    local = skeleton.inverse_bind_matrices[j] @ np.r_[skeleton.tails[j], 1.0]
    return (mats[:, j] @ local)[:, :3]


def foot_points(skeleton, feet, mats):
    """(F, P, 3) model positions of the joints ``feet`` and of their tails, in the poses
    ``mats`` (F, J, 4, 4)."""
    tails = [tail_point(skeleton, mats, j) for j in feet]
    return np.stack([mats[:, j, :3, 3] for j in feet] + [t for t in tails if t is not None],
                    axis=1)


def calibrate(skeleton, clips, what, kind=Calibration):
    """The rest pose when it stands as ``kind`` needs (a humanoid with legs, spine and arms;
    :class:`rigedit.rigging.retarget.limbs.LegCalibration`: legs on the floor), else frame 0 of the
    first clip where it does (a BVH rest may lie all along one axis, as Bandai's does).

    Raises
    ------
    ValueError
        Naming ``what`` and the missing part, when no pose has what ``kind`` needs.
    """
    rest = skeleton.forward(skeleton.rest_local_matrices())
    try:
        return kind(skeleton, rest, "rest", what)
    except ValueError as exc:
        first = exc
    for clip in clips:
        mats = skeleton.forward(clip.sample(0.0).local_matrices())
        try:
            return kind(skeleton, mats, f"frame 0 of {clip.name}", what)
        except ValueError:
            continue
    raise first
