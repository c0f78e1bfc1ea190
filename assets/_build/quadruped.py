"""The elk-like quadruped: skeleton (joint heads in metres, Y up, facing +Z) and shape."""
from __future__ import annotations

import numpy as np

from .sdf import cone, ell, sweep

# name, parent, head, tail (None: bone ends at its child)
_SIDE = ("L", 1.0), ("R", -1.0)


def joints():
    """List of (name, parent, head (3,), tail (3,) or None, deform)."""
    J = [("root", None, (0, 0, 0), None, False),
         ("pelvis", "root", (0, 1.12, -0.55), None, True),
         ("spine_1", "pelvis", (0, 1.14, -0.26), None, True),
         ("spine_2", "spine_1", (0, 1.16, 0.02), None, True),
         ("spine_3", "spine_2", (0, 1.19, 0.28), None, True),
         ("neck_1", "spine_3", (0, 1.28, 0.46), None, True),
         ("neck_2", "neck_1", (0, 1.42, 0.60), None, True),
         ("neck_3", "neck_2", (0, 1.56, 0.70), None, True),
         ("head", "neck_3", (0, 1.68, 0.78), (0, 1.50, 1.20), True),
         ("jaw", "head", (0, 1.60, 0.86), (0, 1.47, 1.14), True)]
    for s, x in _SIDE:
        J += [(f"ear_{s}", "head", (0.07 * x, 1.74, 0.80), (0.23 * x, 1.83, 0.74), True)]
    for s, x in _SIDE:
        J += [(f"antler_{s}_1", "head", (0.05 * x, 1.77, 0.84), None, True),
              (f"antler_{s}_2", f"antler_{s}_1", (0.15 * x, 1.92, 0.80), None, True),
              (f"antler_{s}_3", f"antler_{s}_2", (0.28 * x, 2.04, 0.68), (0.36 * x, 2.15, 0.52),
               True)]
    J += [("tail_1", "pelvis", (0, 1.12, -0.76), None, True),
          ("tail_2", "tail_1", (0, 1.07, -0.82), None, True),
          ("tail_3", "tail_2", (0, 1.01, -0.86), None, True),
          ("tail_4", "tail_3", (0, 0.95, -0.88), (0, 0.89, -0.89), True)]
    for s, x in _SIDE:
        hx = 0.15 * x
        J += [(f"hind_thigh_{s}", "pelvis", (hx, 1.02, -0.56), None, True),
              (f"hind_shin_{s}", f"hind_thigh_{s}", (hx, 0.70, -0.40), None, True),
              (f"hind_cannon_{s}", f"hind_shin_{s}", (hx, 0.48, -0.72), None, True),
              (f"hind_hoof_{s}", f"hind_cannon_{s}", (hx, 0.11, -0.66), (hx, 0.03, -0.58), True)]
    for s, x in _SIDE:
        fx = 0.15 * x
        J += [(f"scapula_{s}", "spine_3", (0.09 * x, 1.24, 0.22), None, True),
              (f"fore_upper_{s}", f"scapula_{s}", (fx, 0.98, 0.38), None, True),
              (f"fore_lower_{s}", f"fore_upper_{s}", (fx, 0.74, 0.24), None, True),
              (f"fore_cannon_{s}", f"fore_lower_{s}", (fx, 0.40, 0.31), None, True),
              (f"fore_hoof_{s}", f"fore_cannon_{s}", (fx, 0.11, 0.32), (fx, 0.03, 0.40), True)]
    return J


def regions():
    """Joint -> region; regions other than core never share a vertex."""
    reg = {}
    for s, _ in _SIDE:
        for n in ("thigh", "shin", "cannon", "hoof"):
            reg[f"hind_{n}_{s}"] = f"hind_{s}"
        for n in ("upper", "lower", "cannon", "hoof"):
            reg[f"fore_{n}_{s}"] = f"fore_{s}"
        reg[f"scapula_{s}"] = f"fore_{s}"
        reg[f"ear_{s}"] = f"ear_{s}"
        for i in (1, 2, 3):
            reg[f"antler_{s}_{i}"] = f"antler_{s}"
    for i in (1, 2, 3, 4):
        reg[f"tail_{i}"] = "tail"
    return reg


def prims(H):
    """Modelling primitives; ``H`` maps joint name -> head (3,) array."""
    P = []
    c = lambda *a, **k: P.append(cone(*a, **k))  # noqa: E731
    e = lambda *a, **k: P.append(ell(*a, **k))  # noqa: E731
    B = 0.09
    # Trunk: one smooth tube from rump to brisket along a spline through the spine, its
    # section an ellipse (narrower at the chest) whose size varies smoothly, so the barrel has
    # no seams where per-joint pieces would meet. The weights still go per spine joint.
    z = np.array([-0.69, -0.56, -0.405, -0.26, -0.12, 0.02, 0.15, 0.34])
    y = np.array([1.09, 1.07, 1.045, 1.03, 1.02, 1.01, 1.02, 1.07])
    r = np.array([0.12, 0.21, 0.245, 0.265, 0.28, 0.29, 0.29, 0.24])
    P.extend(sweep(["pelvis", "pelvis", "spine_1", "spine_1", "spine_2", "spine_2", "spine_3"],
                   np.stack([0 * z, y, z], axis=1), r,
                   squash=(0, 2, [-0.8, -0.56, -0.3, 0.02, 0.27, 0.6],
                           [0.88, 0.9, 0.88, 0.83, 0.72, 0.75]), blend=B))
    # Neck: one tube from inside the chest to the head, deep at the base (throat), slimmer
    # than deep all along.
    P.extend(sweep(["neck_1", "neck_1", "neck_2", "neck_3"],
                   [(0, 1.14, 0.36), (0, 1.28, 0.50), H["neck_2"], H["neck_3"],
                    H["head"] + (0, -0.02, 0.03)],
                   [0.17, 0.15, 0.125, 0.105, 0.095],
                   squash=(0, 2, [0.0, 1.0], [0.8, 0.8]), blend=0.08))
    e("head", (0, 1.67, 0.86), (0.085, 0.095, 0.12), axis_z=(0, -0.35, 1), blend=0.05)
    c("head", (0, 1.65, 0.90), (0, 1.53, 1.15), 0.08, 0.055, blend=0.05)
    e("head", (0, 1.52, 1.16), (0.055, 0.05, 0.055), blend=0.03)
    c("jaw", (0, 1.59, 0.88), (0, 1.48, 1.12), 0.055, 0.035, blend=0.04)
    for s, x in _SIDE:
        # Eyes as slight bulges, ears as flat leaves, antlers as tapered beams with tines.
        e("head", (0.075 * x, 1.68, 0.93), (0.03, 0.025, 0.03), blend=0.02)
        a, b = H[f"ear_{s}"], np.array((0.23 * x, 1.83, 0.74))
        e(f"ear_{s}", (a + b) / 2 + (0, 0, 0), (0.022, 0.045, np.linalg.norm(b - a) / 2 + 0.015),
          axis_z=b - a, axis_y=(0, 0.3, 1), blend=0.02)
        b1, b2, b3 = H[f"antler_{s}_1"], H[f"antler_{s}_2"], H[f"antler_{s}_3"]
        tip = np.array((0.36 * x, 2.15, 0.52))
        c(f"antler_{s}_1", b1, b2, 0.026, 0.022, blend=0.015)
        c(f"antler_{s}_2", b2, b3, 0.022, 0.018, blend=0.012)
        c(f"antler_{s}_3", b3, tip, 0.018, 0.010, blend=0.012)
        c(f"antler_{s}_1", b1 + 0.35 * (b2 - b1), b1 + (0.05 * x, 0.06, 0.16), 0.016, 0.008,
          blend=0.01)
        c(f"antler_{s}_2", b2 + 0.5 * (b3 - b2), b2 + (0.10 * x, 0.20, 0.08), 0.015, 0.007,
          blend=0.01)
        c(f"antler_{s}_3", b3 + 0.4 * (tip - b3), b3 + (0.03 * x, 0.22, 0.02), 0.013, 0.006,
          blend=0.01)
    # Tail: a short flat wedge.
    tips = {"tail_1": H["tail_2"], "tail_2": H["tail_3"], "tail_3": H["tail_4"],
            "tail_4": np.array((0, 0.89, -0.89))}
    radii = {"tail_1": (0.06, 0.05), "tail_2": (0.05, 0.045), "tail_3": (0.045, 0.035),
             "tail_4": (0.035, 0.02)}
    for n, t in tips.items():
        c(n, H[n], t, *radii[n], blend=0.03)
    for s, x in _SIDE:
        hip, sti, hock, fet = (H[f"hind_{n}_{s}"] for n in ("thigh", "shin", "cannon", "hoof"))
        toe = np.array((0.15 * x, 0.03, -0.58))
        # Haunch muscle, gaskin, cannon, fetlock, hoof.
        e(f"hind_thigh_{s}", (0.13 * x, 0.92, -0.52), (0.09, 0.20, 0.15), axis_z=(0, 0.2, 1),
          blend=0.06)
        c(f"hind_thigh_{s}", hip, sti, 0.10, 0.07, blend=0.05)
        c(f"hind_shin_{s}", sti, hock, 0.065, 0.035, blend=0.04)
        c(f"hind_shin_{s}", sti + 0.3 * (hock - sti) + (0, 0, -0.02), hock + (0, 0.02, -0.04),
          0.05, 0.025, blend=0.03)
        c(f"hind_cannon_{s}", hock, fet, 0.035, 0.027, blend=0.025)
        c(f"hind_hoof_{s}", fet, toe, 0.03, 0.032, blend=0.02)
        e(f"hind_hoof_{s}", toe + (0, 0.0, -0.01), (0.036, 0.03, 0.045), blend=0.02)
        sca, sho, elb, carp, ffet = (H[f"{n}_{s}"] for n in (
            "scapula", "fore_upper", "fore_lower", "fore_cannon", "fore_hoof"))
        ftoe = np.array((0.15 * x, 0.03, 0.40))
        e(f"scapula_{s}", (sca + sho) / 2, (0.07, 0.17, 0.12), axis_z=(0, 0.3, 1), blend=0.06)
        c(f"fore_upper_{s}", sho, elb, 0.09, 0.075, blend=0.05)
        c(f"fore_lower_{s}", elb, carp, 0.06, 0.032, blend=0.04)
        c(f"fore_cannon_{s}", carp, ffet, 0.032, 0.026, blend=0.025)
        c(f"fore_hoof_{s}", ffet, ftoe, 0.03, 0.032, blend=0.02)
        e(f"fore_hoof_{s}", ftoe + (0, 0.0, -0.01), (0.036, 0.03, 0.045), blend=0.02)
    return P
