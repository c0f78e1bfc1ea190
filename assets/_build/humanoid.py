"""The humanoid: mocap-style joint names, T-pose, 1.75 m, Y up, facing +Z (left = +X)."""
from __future__ import annotations

import numpy as np

from .sdf import cone, ell, sweep

_SIDE = (("Left", 1.0), ("Right", -1.0))


def joints():
    J = [("root", None, (0, 0, 0), None, False),
         ("Hips", "root", (0, 0.98, 0), None, True),
         ("Spine", "Hips", (0, 1.08, 0.0), None, True),
         ("Spine1", "Spine", (0, 1.20, -0.005), None, True),
         ("Spine2", "Spine1", (0, 1.32, -0.01), None, True),
         ("Neck", "Spine2", (0, 1.50, -0.01), None, True),
         ("Head", "Neck", (0, 1.58, 0.0), (0, 1.76, 0.01), True)]
    for s, x in _SIDE:
        J += [(f"{s}Shoulder", "Spine2", (0.03 * x, 1.44, -0.01), None, True),
              (f"{s}Arm", f"{s}Shoulder", (0.17 * x, 1.45, -0.02), None, True),
              (f"{s}ForeArm", f"{s}Arm", (0.45 * x, 1.45, -0.02), None, True),
              (f"{s}Hand", f"{s}ForeArm", (0.71 * x, 1.45, -0.02), (0.88 * x, 1.45, -0.02), True)]
    for s, x in _SIDE:
        J += [(f"{s}UpLeg", "Hips", (0.09 * x, 0.93, 0.0), None, True),
              (f"{s}Leg", f"{s}UpLeg", (0.09 * x, 0.51, 0.005), None, True),
              (f"{s}Foot", f"{s}Leg", (0.09 * x, 0.09, -0.02), None, True),
              (f"{s}ToeBase", f"{s}Foot", (0.09 * x, 0.03, 0.12), (0.09 * x, 0.03, 0.20), True)]
    return J


def regions():
    reg = {}
    for s, _ in _SIDE:
        for n in ("UpLeg", "Leg", "Foot", "ToeBase"):
            reg[f"{s}{n}"] = f"{s}_leg"
        for n in ("Shoulder", "Arm", "ForeArm", "Hand"):
            reg[f"{s}{n}"] = f"{s}_arm"
    return reg


def prims(H):
    P = []
    c = lambda *a, **k: P.append(cone(*a, **k))  # noqa: E731
    e = lambda *a, **k: P.append(ell(*a, **k))  # noqa: E731
    B = 0.06
    e("Hips", (0, 0.95, -0.005), (0.16, 0.11, 0.11), blend=B)
    # Torso: one smooth tube up the spine (section wider than deep, varying smoothly), so
    # the waist and ribs show no seams; the weights still go per spine joint.
    P.extend(sweep(["Hips", "Spine", "Spine1", "Spine2"],
                   [(0, 0.93, -0.005), (0, 1.02, 0.0), (0, 1.155, 0.0), (0, 1.285, -0.005),
                    (0, 1.41, -0.01)], [0.13, 0.138, 0.145, 0.16, 0.13],
                   squash=(2, 1, [0.9, 1.09, 1.22, 1.35, 1.5], [0.7, 0.68, 0.7, 0.68, 0.68]),
                   blend=B))
    e("Spine2", (0, 1.30, 0.045), (0.13, 0.08, 0.07), blend=B)   # chest
    c("Neck", (0, 1.44, -0.015), (0, 1.61, 0.0), 0.055, 0.048, blend=0.04)
    e("Head", (0, 1.675, 0.01), (0.078, 0.10, 0.098), blend=0.04)
    e("Head", (0, 1.62, 0.04), (0.062, 0.06, 0.07), blend=0.04)      # jaw
    e("Head", (0, 1.662, 0.10), (0.014, 0.024, 0.02), blend=0.015)   # nose
    for s, x in _SIDE:
        e("Hips", (0.07 * x, 0.90, -0.055), (0.085, 0.09, 0.07), blend=B)   # buttock
        e("Head", (0.08 * x, 1.667, 0.0), (0.012, 0.028, 0.018), blend=0.012)  # ear
        sh, arm, fa, hand = (H[f"{s}{n}"] for n in ("Shoulder", "Arm", "ForeArm", "Hand"))
        # Limbs as one tube each (no bulge at elbow and knee where two pieces would blend).
        P.extend(sweep([f"{s}Shoulder", f"{s}Arm", f"{s}ForeArm"],
                       [sh + (0, -0.02, 0), arm, fa, hand], [0.06, 0.053, 0.04, 0.03],
                       blend=0.05))
        e(f"{s}Hand", hand + (0.075 * x, 0, 0), (0.075, 0.02, 0.045), axis_z=(1, 0, 0),
          blend=0.02)
        c(f"{s}Hand", hand + (0.02 * x, -0.005, 0.03), hand + (0.07 * x, -0.01, 0.065), 0.014,
          0.011, blend=0.015)   # thumb
        up, kn, an, toe = (H[f"{s}{n}"] for n in ("UpLeg", "Leg", "Foot", "ToeBase"))
        P.extend(sweep([f"{s}UpLeg", f"{s}Leg"], [up, kn, an], [0.085, 0.053, 0.037],
                       blend=0.05))
        e(f"{s}Leg", (0.09 * x, 0.37, -0.025), (0.05, 0.11, 0.05), blend=0.04)   # calf
        e(f"{s}Foot", (0.09 * x, 0.045, 0.025), (0.045, 0.04, 0.1), axis_z=(0, -0.05, 1),
          blend=0.03)
        c(f"{s}ToeBase", toe + (0, 0.0, 0.0), toe + (0, -0.005, 0.075), 0.033, 0.027,
          blend=0.02)
    return P
