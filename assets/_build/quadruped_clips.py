"""The quadruped's clips: idle, head_nod, walk (four-beat), run (trot), with leg IK."""
from __future__ import annotations

import numpy as np

from rigedit.model.pose import Pose

from .gait import PlanarChain, bake, foot_track, qeuler, qx, x_angle, yz

SIDES = ("L", "R")


class Locomotion:
    """Pose generator: body motion from ``body_fn``, legs by IK to foot trajectories."""

    def __init__(self, sk, period, stride, duty, phases, lift, fold=1.0, curl=(1.2, 0.9),
                 body_fn=None, scapula_gain=0.35):
        self.sk, self.T, self.S, self.duty, self.phases = sk, period, stride, duty, phases
        self.lift, self.fold, self.curl, self.body_fn = lift, fold, curl, body_fn
        self.scapula_gain = scapula_gain
        self.legs = {}
        for s in SIDES:
            self.legs[f"hind_{s}"] = PlanarChain(
                sk, [f"hind_thigh_{s}", f"hind_shin_{s}", f"hind_cannon_{s}", f"hind_hoof_{s}"],
                stance=(0.8, -1.0), fold=(0.35, -0.9), s_range=(-1.2, 1.2))
            self.legs[f"fore_{s}"] = PlanarChain(
                sk, [f"fore_upper_{s}", f"fore_lower_{s}", f"fore_cannon_{s}", f"fore_hoof_{s}"],
                stance=(-1.0, 0.05), fold=(-0.25, 1.1), s_range=(-1.0, 1.2))
        self.rest_end = {k: yz(sk.bind_matrices[c.idx[-1], :3, 3]) for k, c in self.legs.items()}
        self.sole = {}
        for k, c in self.legs.items():
            j = c.idx[-1]
            toe = yz(sk.tails[j]) - yz(sk.bind_matrices[j, :3, 3])
            # Points of the sole (front, middle, heel of the hoof's bottom), fetlock-relative.
            self.sole[k] = toe + np.array([-0.03 + 0.045j, -0.03 + 0.0j, -0.03 - 0.045j])
        self.max_miss = 0.0

    def __call__(self, t):
        sk = self.sk
        pose = Pose(sk)
        body_z = self.S * t / self.T
        pose.translation[0] = sk.rest_translation[0] + [0, 0, body_z]
        feet = {}
        for leg in self.legs:
            dz, ly, s = foot_track(t, self.T, self.phases.get(leg, 0.0), self.duty, self.S,
                                   self.lift)
            feet[leg] = (dz, ly, s)
        if self.body_fn:
            self.body_fn(pose, t)
        for s in SIDES:  # the scapula follows its foot, as the shoulder blade swings
            rel = feet[f"fore_{s}"][0] - body_z
            j = sk.joint_index(f"scapula_{s}")
            pose.rotation[j] = qx(-self.scapula_gain * rel)
        M = sk.forward(pose.local_matrices())
        for leg, chain in self.legs.items():
            dz, ly, s = feet[leg]
            f = self.fold * np.sin(np.pi * s) ** 2 if s > 0 else 0.0
            curl = self.curl[0] if leg.startswith("fore") else self.curl[1]
            w = f / max(self.fold, 1e-9)
            top = yz(M[chain.idx[0], :3, 3])
            parent = x_angle(M[chain.parent])
            # Turning the hoof lowers its toe or its heel: lift the fetlock by the deepest
            # dip of the hoof's sole points so a hoof that folds in the swing never goes
            # below the ground (a few passes: the hoof's turn depends on the cannon's).
            raise_by = 0.0
            for _ in range(3):
                target = self.rest_end[leg] + complex(ly + raise_by, dz)
                alphas, miss = chain.solve(top, target, f)
                hoof_world = w * (alphas[-1] + curl)
                sole = self.sole[leg]
                dip = float(np.max(sole.real - (sole * np.exp(1j * hoof_world)).real))
                if dip <= raise_by + 1e-4:
                    break
                raise_by = dip
            self.max_miss = max(self.max_miss, miss)
            prev = parent
            for j, a in zip(chain.idx[:-1], alphas):
                pose.rotation[j] = qx(a - prev)
                prev = a
            pose.rotation[chain.idx[-1]] = qx(hoof_world - alphas[-1])
        return pose


def _set(pose, name, q):
    pose.rotation[pose.skeleton.joint_index(name)] = q


def make_clips(sk, log=print):
    clips = {}
    tau = 2 * np.pi
    rest_pelvis = sk.rest_translation[sk.joint_index("pelvis")]

    # idle: breathing, a slow look around, ear flicks, tail flick; hooves stay planted.
    T = 4.0

    def idle_body(pose, t):
        w = tau * t / T
        breath = np.sin(2 * w)
        pose.translation[1] = rest_pelvis + [0, 0.004 * breath, 0]
        _set(pose, "spine_1", qx(0.006 * breath))
        _set(pose, "spine_2", qx(-0.008 * breath))
        _set(pose, "neck_1", qx(0.05 * np.sin(w)))
        _set(pose, "neck_3", qeuler(y=12 * np.sin(w), x=-3 * np.sin(w)))
        _set(pose, "head", qeuler(x=-6 * np.sin(w + 0.6), z=3 * np.sin(2 * w)))
        flick = np.exp(-((t % T - 1.3) / 0.12) ** 2) + np.exp(-((t % T - 3.1) / 0.12) ** 2)
        _set(pose, "ear_L", qeuler(z=-18 * flick, y=6 * np.sin(w)))
        _set(pose, "ear_R", qeuler(z=14 * np.exp(-((t % T - 2.2) / 0.12) ** 2), y=6 * np.sin(w)))
        _set(pose, "tail_1", qeuler(y=10 * np.sin(3 * w)))
        _set(pose, "tail_2", qeuler(y=8 * np.sin(3 * w - 0.8)))
        _set(pose, "jaw", qx(-0.05 * max(0.0, np.sin(4 * w)) ** 2))

    loco = Locomotion(sk, T, 0.0, 1.0, {}, 0.0, body_fn=idle_body)
    clips["idle"] = bake("idle", sk, loco, T, fps=15, translate=())

    # head_nod: two nods.
    T = 2.0

    def nod_body(pose, t):
        b = 0.5 - 0.5 * np.cos(2 * tau * t / T)
        _set(pose, "neck_1", qx(0.12 * b))
        _set(pose, "neck_2", qx(0.10 * b))
        _set(pose, "neck_3", qx(0.08 * b))
        _set(pose, "head", qx(0.30 * b))
        _set(pose, "ear_L", qeuler(z=-10 * b))
        _set(pose, "ear_R", qeuler(z=10 * b))

    loco = Locomotion(sk, T, 0.0, 1.0, {}, 0.0, body_fn=nod_body)
    clips["head_nod"] = bake("head_nod", sk, loco, T, fps=30, translate=())

    # walk: lateral-sequence four-beat walk (LH, LF, RH, RF a quarter cycle apart).
    T, S = 1.15, 0.9

    def walk_body(pose, t):
        w = tau * t / T
        pose.translation[1] = rest_pelvis + [0, -0.035 + 0.01 * np.cos(2 * w), 0]
        _set(pose, "pelvis", qx(0.015 * np.sin(2 * w)))
        _set(pose, "neck_1", qx(0.05 * np.sin(2 * w + 1.0)))
        _set(pose, "head", qx(-0.04 * np.sin(2 * w + 1.0)))
        _set(pose, "tail_1", qeuler(y=6 * np.sin(w)))
        _set(pose, "tail_2", qeuler(y=6 * np.sin(w - 0.7)))
        _set(pose, "ear_L", qeuler(z=-4 * np.sin(2 * w)))
        _set(pose, "ear_R", qeuler(z=4 * np.sin(2 * w)))

    phases = {"hind_L": 0.0, "fore_L": 0.25, "hind_R": 0.5, "fore_R": 0.75}
    loco = Locomotion(sk, T, S, 0.62, phases, 0.13, body_fn=walk_body, scapula_gain=0.5)
    clips["walk"] = bake("walk", sk, loco, T, fps=30)
    log(f"  walk: IK miss max {loco.max_miss * 1000:.1f} mm")

    # run: a trot (diagonal pairs), with a suspension phase.
    T, S = 0.6, 1.7

    def run_body(pose, t):
        w = tau * t / T
        pose.translation[1] = rest_pelvis + [0, -0.04 - 0.03 * np.cos(2 * (w - 0.2 * tau)), 0]
        _set(pose, "pelvis", qx(0.02 * np.sin(2 * w)))
        _set(pose, "neck_1", qx(0.06 * np.sin(2 * w + 0.8)))
        _set(pose, "head", qx(-0.05 * np.sin(2 * w + 0.8)))
        _set(pose, "tail_1", qeuler(x=-15))
        _set(pose, "tail_2", qeuler(x=-8 + 6 * np.sin(2 * w)))
        _set(pose, "ear_L", qeuler(x=-10, z=8))
        _set(pose, "ear_R", qeuler(x=-10, z=-8))

    phases = {"hind_L": 0.0, "fore_R": 0.0, "hind_R": 0.5, "fore_L": 0.5}
    loco = Locomotion(sk, T, S, 0.4, phases, 0.2, body_fn=run_body, scapula_gain=0.5)
    clips["run"] = bake("run", sk, loco, T, fps=30)
    log(f"  run: IK miss max {loco.max_miss * 1000:.1f} mm")
    return clips
