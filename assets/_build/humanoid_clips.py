"""The humanoid's clips: idle, wave, walk (feet planted, heel-off about the ball of the foot)."""
from __future__ import annotations

import numpy as np

from rigedit.model.pose import Pose

from .gait import PlanarChain, bake, foot_track, qeuler, qx, x_angle, yz

SIDES = (("Left", 1.0), ("Right", -1.0))
ARM_DOWN = 72.0   # degrees from the T-pose to relaxed arms


def _set(pose, name, q):
    pose.rotation[pose.skeleton.joint_index(name)] = q


def _smooth(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def arms_down(pose, fwd_L=0.0, fwd_R=0.0, bend=15.0):
    """Relaxed arms; ``fwd_*`` swings an arm forward (degrees)."""
    for s, x in SIDES:
        fwd = fwd_L if x > 0 else fwd_R
        _set(pose, f"{s}Arm", qeuler(z=-x * ARM_DOWN, x=-fwd))
        _set(pose, f"{s}ForeArm", qeuler(y=-x * (bend + max(fwd, 0.0) * 0.5)))
        _set(pose, f"{s}Hand", qeuler(z=-x * 5))


class Walker:
    """Biped walk: the ball of each foot is planted in stance; the heel lifts at its end."""

    def __init__(self, sk, period, stride, duty, lift, heel=28.0, body_fn=None):
        self.sk, self.T, self.S, self.duty, self.lift = sk, period, stride, duty, lift
        self.heel = np.radians(heel)
        self.body_fn = body_fn
        self.legs, self.ball, self.ankle_off = {}, {}, {}
        for s, x in SIDES:
            self.legs[s] = PlanarChain(sk, [f"{s}UpLeg", f"{s}Leg", f"{s}Foot"], stance=(1.0,),
                                       fold=(0.0,), s_range=(-0.05, 2.2))
            b = yz(sk.bind_matrices[sk.joint_index(f"{s}ToeBase"), :3, 3])
            a = yz(sk.bind_matrices[sk.joint_index(f"{s}Foot"), :3, 3])
            self.ball[s], self.ankle_off[s] = b, a - b
        self.phase = {"Left": 0.0, "Right": 0.5}
        self.max_miss = 0.0

    def foot(self, s, t):
        """Ball offset (z, lift), foot pitch (heel up > 0), toe pitch, swing fold."""
        dz, ly, sw = foot_track(t, self.T, self.phase[s], self.duty, self.S, self.lift)
        p = (t / self.T - self.phase[s]) % 1.0
        if sw == 0.0:
            theta = self.heel * _smooth((p - 0.6 * self.duty) / (0.4 * self.duty))
            return dz, ly, theta, 1.0, 0.0
        theta = self.heel * (1 - _smooth(sw / 0.7)) - 0.25 * np.sin(np.pi * sw) ** 2
        toe = 1.0 - _smooth((sw - 0.1) / 0.3)   # the toe unrolls from flat to straight
        fold = np.sin(np.pi * sw) ** 2
        return dz, ly, theta, toe, fold

    def __call__(self, t):
        sk = self.sk
        pose = Pose(sk)
        pose.translation[0] = sk.rest_translation[0] + [0, 0, self.S * t / self.T]
        if self.body_fn:
            self.body_fn(pose, t)
        M = sk.forward(pose.local_matrices())
        for s, chain in self.legs.items():
            dz, ly, theta, toe, fold = self.foot(s, t)
            # Lift the ball by the deepest dip of the toe tip and heel below it so the
            # turning foot never scrapes the ground in the swing.
            dip = max(0.0, -0.09 * np.sin(-theta * (1 - toe)), -0.17 * np.sin(theta)) \
                if fold > 0 else 0.0
            ball = self.ball[s] + complex(ly + dip, dz)
            target = ball + np.exp(1j * theta) * self.ankle_off[s]
            alphas, miss = chain.solve(yz(M[chain.idx[0], :3, 3]), target, fold)
            self.max_miss = max(self.max_miss, miss)
            prev = x_angle(M[chain.parent])
            for j, a in zip(chain.idx[:-1], alphas):
                pose.rotation[j] = qx(a - prev)
                prev = a
            _set(pose, f"{s}Foot", qx(theta - prev))
            # Toe world pitch: flat (0) while planted, following the foot once unrolled.
            _set(pose, f"{s}ToeBase", qx(-theta * toe))
        return pose


def make_clips(sk, log=print):
    clips = {}
    tau = 2 * np.pi
    rest_hips = sk.rest_translation[sk.joint_index("Hips")]

    T = 4.0

    def idle(t):
        pose = Pose(sk)
        w = tau * t / T
        breath = np.sin(2 * w)
        arms_down(pose, fwd_L=2 * np.sin(w), fwd_R=2 * np.sin(w + 1))
        _set(pose, "Spine1", qx(-0.012 * breath))
        _set(pose, "Spine2", qx(-0.01 * breath))
        for s, x in SIDES:
            _set(pose, f"{s}Shoulder", qeuler(z=x * 1.5 * breath))
        _set(pose, "Neck", qeuler(y=4 * np.sin(w)))
        _set(pose, "Head", qeuler(y=8 * np.sin(w), x=3 * np.sin(2 * w + 0.5)))
        return pose

    clips["idle"] = bake("idle", sk, idle, T, fps=15, translate=())

    T = 3.0

    def wave(t):
        pose = Pose(sk)
        env = _smooth(t / 0.6) * (1 - _smooth((t - 2.4) / 0.6))
        arms_down(pose)
        osc = np.sin(tau * (t - 0.6) / 0.6) * _smooth((t - 0.5) / 0.3) * (
            1 - _smooth((t - 2.3) / 0.3))
        _set(pose, "RightArm", qeuler(z=ARM_DOWN + env * (-35 - ARM_DOWN), x=-10 * env))
        _set(pose, "RightForeArm", qeuler(y=15 * (1 - env), z=env * (-72 + 20 * osc)))
        _set(pose, "RightHand", qeuler(z=8 * osc * env, y=-10 * env))
        _set(pose, "RightShoulder", qeuler(z=-6 * env))
        _set(pose, "Spine2", qeuler(z=2 * env, y=-4 * env))
        _set(pose, "Head", qeuler(z=-4 * env, y=-6 * env, x=-3 * env))
        return pose

    clips["wave"] = bake("wave", sk, wave, T, fps=30, translate=())

    T, S = 1.1, 1.15

    def walk_body(pose, t):
        w = tau * t / T
        pose.translation[1] = rest_hips + [0, -0.06 + 0.015 * np.cos(2 * (w - 0.3 * tau)), 0]
        _set(pose, "Spine", qx(0.03))
        _set(pose, "Spine2", qeuler(y=5 * np.cos(w)))
        _set(pose, "Neck", qeuler(y=-3 * np.cos(w)))
        _set(pose, "Head", qx(-0.03))
        arms_down(pose, fwd_L=-18 * np.cos(w), fwd_R=18 * np.cos(w))

    walker = Walker(sk, T, S, 0.6, 0.07, body_fn=walk_body)
    clips["walk"] = bake("walk", sk, walker, T, fps=30)
    log(f"  walk: IK miss max {walker.max_miss * 1000:.1f} mm")
    return clips
