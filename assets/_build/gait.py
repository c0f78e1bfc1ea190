"""Leg IK in the sagittal (Y-Z) plane, foot trajectories, and baking poses into clips.

Legs hang in planes x = const and every joint above and along them turns about the model X
axis only, so a leg is a planar chain: a point is the complex number y + i z and a turn about
+X by a multiplies it by exp(i a).
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from rigedit.animation import Clip, Track


def yz(p):
    return complex(p[1], p[2])


def qx(a):
    """Quaternion (x, y, z, w) of a turn about X by ``a`` radians."""
    return np.array([np.sin(a / 2), 0.0, 0.0, np.cos(a / 2)])


def qeuler(x=0.0, y=0.0, z=0.0):
    """Quaternion of Euler angles in degrees, X then Y then Z (as Pose.set_euler)."""
    return Rotation.from_euler("xyz", [x, y, z], degrees=True).as_quat()


def x_angle(mat):
    """Angle of a pure X rotation from a (4, 4) or (3, 3) matrix."""
    return float(np.arctan2(mat[2, 1], mat[1, 1]))


class PlanarChain:
    """A leg: top joint, intermediate joints, end joint (the contact joint's head).

    Parameters
    ----------
    skeleton : Skeleton
    names : list[str]
        Joints from the top of the leg to the joint whose head is placed (e.g. hip, knee,
        ankle); the bones are between consecutive heads.
    stance : sequence of float
        Direction of flexion per inner joint, used to fit the chain length (s >= 0 flexes).
    fold : sequence of float
        Extra flexion per inner joint at full swing fold.
    s_range : (float, float)
    """

    def __init__(self, skeleton, names, stance, fold, s_range=(-1.0, 2.0)):
        self.names = list(names)
        self.idx = [skeleton.joint_index(n) for n in names]
        heads = skeleton.bind_matrices[self.idx, :3, 3]
        pts = np.array([yz(h) for h in heads])
        bones = np.diff(pts)
        self.L = np.abs(bones)
        self.psi = np.angle(bones)
        self.rho = np.diff(self.psi)
        self.A = np.asarray(stance, float)
        self.B = np.asarray(fold, float)
        self.s = np.linspace(s_range[0], s_range[1], 601)
        self.parent = skeleton.parents[self.idx[0]]

    def _vectors(self, fold):
        delta = self.s[:, None] * self.A[None] + fold * self.B[None]     # (S, n-1)
        ang = self.psi[0] + np.concatenate([np.zeros((len(self.s), 1)),
                                            np.cumsum(self.rho[None] + delta, axis=1)], axis=1)
        return (self.L[None] * np.exp(1j * ang)).sum(axis=1), ang

    def solve(self, top, target, fold=0.0):
        """World turns (about X, relative to rest) of each bone so the end reaches ``target``.

        Returns
        -------
        alphas : (n,) float
            Rest-relative world X turn of each bone (one per joint but the last).
        miss : float
            Distance left between the chain's end and the target (0 when reachable).
        """
        W = target - top
        V, ang = self._vectors(fold)
        r = np.abs(V)
        # |V| falls as s flexes the chain; keep the part of the table where it does (past the
        # longest reach, over-extension would shorten it again) and pick the s matching |W|.
        first = int(np.argmax(r))
        last = first + int(np.argmin(r[first:]))
        seg = r[first:last + 1][::-1]
        i = first + (len(seg) - 1) - np.interp(abs(W), seg, np.arange(len(seg), dtype=float))
        lo = int(np.floor(i)); hi = min(lo + 1, len(r) - 1); f = i - lo
        a = ang[lo] * (1 - f) + ang[hi] * f
        Vi = (self.L * np.exp(1j * a)).sum()
        turn = np.angle(W) - np.angle(Vi)
        miss = abs(abs(W) - abs(Vi))
        return a + turn - self.psi, miss


def swing_ease(s):
    """0 -> 1 with zero speed at both ends (a cycloid)."""
    return s - np.sin(2 * np.pi * s) / (2 * np.pi)


def foot_track(t, period, phase, duty, stride, lift):
    """Forward offset (world, from the rest position at t=0 of the body), lift and swing
    progress of a foot.

    Stance for leg phase p in [0, duty): the foot is still on the ground; the body moves
    ``stride`` per period, so relative to the body the foot goes from +stride*duty/2 to
    -stride*duty/2. Swing: it catches up by one stride along a cycloid, lifted by
    ``lift * sin(pi s)^2``.

    Returns z offset, y lift, swing progress s (0 in stance).
    """
    u = t / period - phase
    k = np.floor(u)
    p = u - k
    base = stride * (duty / 2 + phase + k)
    if p < duty:
        return base, 0.0, 0.0
    s = (p - duty) / (1 - duty)
    return base + stride * swing_ease(s), lift * np.sin(np.pi * s) ** 2, s


def bake(name, skeleton, pose_fn, duration, fps=30, loop=True, joints=None,
         translate=("root",)):
    """Sample ``pose_fn(t) -> Pose`` at ``fps`` into a clip of rotation tracks (all joints
    that move, or ``joints``) and translation tracks for the joints in ``translate``."""
    n = max(2, int(round(duration * fps)))
    times = np.linspace(0.0, duration, n + 1)
    poses = [pose_fn(t) for t in times]
    R = np.stack([p.rotation for p in poses])      # (K, J, 4)
    T = np.stack([p.translation for p in poses])
    tracks = {}
    for j, jn in enumerate(skeleton.names):
        moves = np.abs(np.abs(np.sum(R[:, j] * skeleton.rest_rotation[j], axis=1)) - 1).max() > 1e-9
        if (joints is None and moves) or (joints is not None and jn in joints):
            tracks[(jn, "rotation")] = Track("rotation", times, R[:, j], "slerp")
        if jn in translate or np.abs(T[:, j] - skeleton.rest_translation[j]).max() > 1e-9:
            tracks[(jn, "translation")] = Track("translation", times, T[:, j], "linear")
    return Clip(name, skeleton, tracks, duration, loop)
