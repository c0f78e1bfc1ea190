"""Synthetic BVH humanoids for tests: a 1.72 m figure (centimetres) walking or dashing, with
or without a carrier root, its rest standing or lying along an axis (as Bandai's does).

The motion is written from the figure's world pose: the hips at ``start + velocity * t``
turned ``yaw(t)`` degrees about +Y (0 faces +Z), the legs swinging in opposite phase, both
thighs turned ``twist(t)`` degrees about their own vertical axis (feet pointing off the
pelvis, as mid-stride), the arms hanging still.
"""
import warnings

import numpy as np
from scipy.spatial.transform import Rotation

HIPS_HEIGHT = 95.0   # cm: thigh 42, shin 40, ankle to toe 6 and 5 below the hips
#: (name, parent, offset cm) of the standing figure, parents first.
JOINTS = [("Hips", None, (0, 0, 0)),
          ("LeftUpLeg", "Hips", (9, -5, 0)), ("LeftLeg", "LeftUpLeg", (0, -42, 0)),
          ("LeftFoot", "LeftLeg", (0, -40, 0)), ("LeftToe", "LeftFoot", (0, -6, 12)),
          ("RightUpLeg", "Hips", (-9, -5, 0)), ("RightLeg", "RightUpLeg", (0, -42, 0)),
          ("RightFoot", "RightLeg", (0, -40, 0)), ("RightToe", "RightFoot", (0, -6, 12)),
          ("Spine", "Hips", (0, 10, 0)), ("Chest", "Spine", (0, 20, 0)),
          ("Neck", "Chest", (0, 22, 0)), ("Head", "Neck", (0, 10, 0)),
          ("LeftShoulder", "Chest", (5, 18, 0)), ("LeftArm", "LeftShoulder", (12, 0, 0)),
          ("LeftForeArm", "LeftArm", (0, -28, 0)), ("LeftHand", "LeftForeArm", (0, -25, 0)),
          ("RightShoulder", "Chest", (-5, 18, 0)), ("RightArm", "RightShoulder", (-12, 0, 0)),
          ("RightForeArm", "RightArm", (0, -28, 0)),
          ("RightHand", "RightForeArm", (0, -25, 0))]
ENDS = {"LeftToe": (0, 0, 5), "RightToe": (0, 0, 5), "Head": (0, 15, 0),
        "LeftHand": (0, -10, 0), "RightHand": (0, -10, 0)}
#: The lying rest: every offset turned -90 degrees about X (the figure lies along +Z).
LYING = Rotation.from_euler("x", -90, degrees=True)


def _locals(t, stride_hz, swing, twist):
    """{joint: Rotation} local rotations of the standing figure at times ``t`` (F,)."""
    phase = 2 * np.pi * stride_hz * t
    out = {}
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        turn = Rotation.from_euler("y", np.broadcast_to(twist(t), t.shape)[:, None],
                                   degrees=True)
        out[f"{side}UpLeg"] = turn * Rotation.from_euler(
            "x", (sign * swing * np.sin(phase))[:, None], degrees=True)
        bend = 0.5 * swing * (1 - np.cos(phase + (0 if sign > 0 else np.pi)))
        out[f"{side}Leg"] = Rotation.from_euler("x", bend[:, None], degrees=True)
    return out


def humanoid_bvh(seconds=2.0, fps=30, velocity=(0.0, 0.0, 120.0), start=(0.0, 0.0, 0.0),
                 yaw=lambda t: 0.0 * t, twist=lambda t: 0.0 * t, carrier=None,
                 lying=False, stride_hz=1.0, swing=25.0, unit=1.0):
    """BVH text of the figure (see the module notes).

    Parameters
    ----------
    velocity, start : (3,) float
        cm per second and cm: the hips' path on the floor (start's y is added to the hips'
        height).
    yaw, twist : callable (F,) seconds -> (F,) degrees
    carrier : str, optional
        The name of a carrier root written above the hips: at the origin, never moving
        (Bandai's ``joint_Root``); the hips carry the whole path.
    lying : bool
        Write the rest lying along +Z (the offsets turned, the motion turned back).
    unit : float
        File units per centimetre (10: millimetres).
    """
    t = np.arange(int(round(seconds * fps)) + 1) / fps
    names = [j[0] for j in JOINTS]
    local = _locals(t, stride_hz, swing, twist)
    hips_rot = Rotation.from_euler("y", np.broadcast_to(yaw(t), t.shape)[:, None],
                                   degrees=True)
    hips_pos = np.asarray(start, float) + [0, HIPS_HEIGHT, 0] + t[:, None] * velocity
    lie = LYING if lying else Rotation.identity()
    lines, columns = ["HIERARCHY"], []
    depth = 0
    if carrier:
        lines += [f"ROOT {carrier}", "{", "  OFFSET 0 0 0",
                  "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"]
        columns.append(np.zeros((len(t), 6)))
        depth = 1

    def write(j, depth):
        name, parent, offset = JOINTS[j]
        pad = "  " * depth
        off = lie.apply(np.asarray(offset, float)) * unit
        is_root = parent is None
        kind = "ROOT" if is_root and not carrier else "JOINT"
        if is_root:
            off = hips_pos[0] * unit
        lines.extend([f"{pad}{kind} {name}", f"{pad}{{",
                      f"{pad}  OFFSET {off[0]:.6f} {off[1]:.6f} {off[2]:.6f}"])
        if is_root:
            lines.append(f"{pad}  CHANNELS 6 Xposition Yposition Zposition Zrotation "
                         f"Xrotation Yrotation")
            rot = hips_rot * lie.inv()
            columns.append(np.c_[hips_pos * unit, rot.as_euler("ZXY", degrees=True)])
        else:
            lines.append(f"{pad}  CHANNELS 3 Zrotation Xrotation Yrotation")
            r = local.get(name, Rotation.identity(len(t)))
            columns.append((lie * r * lie.inv()).as_euler("ZXY", degrees=True))
        kids = [k for k, jt in enumerate(JOINTS) if jt[1] == name]
        for k in kids:
            write(k, depth + 1)
        if name in ENDS:
            e = lie.apply(np.asarray(ENDS[name], float)) * unit
            lines.extend([f"{pad}  End Site", f"{pad}  {{",
                          f"{pad}    OFFSET {e[0]:.6f} {e[1]:.6f} {e[2]:.6f}", f"{pad}  }}"])
        lines.append(f"{pad}}}")

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)   # gimbal lock: the angles still hold
        write(names.index("Hips"), depth)
    if carrier:
        lines.append("}")
    data = np.concatenate(columns, axis=1)
    lines += ["MOTION", f"Frames: {len(t)}", f"Frame Time: {1 / fps:.10g}"]
    lines += [" ".join(f"{v:.6f}" for v in row) for row in data]
    return "\n".join(lines) + "\n"


def dash_yaw(seconds, turn=90.0, settle=0.3):
    """A dash that starts facing ``turn`` degrees across its path and turns onto it in the
    first ``settle`` of the clip."""
    return lambda t: turn * np.clip(1 - t / (settle * seconds), 0, 1)


def dash_twist(seconds, twist=-30.0, settle=0.3):
    """Feet turned ``twist`` degrees off the pelvis at frame 0 (mid-stride), square by the
    end of the turn."""
    return lambda t: twist * np.clip(1 - t / (settle * seconds), 0, 1)
