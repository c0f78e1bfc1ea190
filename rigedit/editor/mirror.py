"""Left and right: joint names' sides, the mirror map of a skeleton, and a pose reflected from
one side onto the other (the joint panel's Mirror buttons). Pure numpy.
"""
from __future__ import annotations

import numpy as np

__all__ = ["mirror_name", "mirror_map", "mirror_pose", "side_axis"]


_MIRROR_PAIRS = [("_L", "_R"), ("_l", "_r"), (".L", ".R"), (".l", ".r"), ("Left", "Right"),
                 ("left", "right"), ("L_", "R_"), ("l_", "r_")]


def mirror_name(name):
    """The name of the other side's joint (``arm_L`` -> ``arm_R``, ``LeftHand`` ->
    ``RightHand``), or None when the name has no side."""
    for a, b in _MIRROR_PAIRS:
        for x, y in ((a, b), (b, a)):
            if x in ("L_", "R_", "l_", "r_"):
                if name.startswith(x):
                    return y + name[len(x):]
            elif x in ("_L", "_R", "_l", "_r", ".L", ".R", ".l", ".r"):
                if name.endswith(x):
                    return name[:-len(x)] + y
                if x + "_" in name or x + "." in name:  # thigh_L_01 style
                    return name.replace(x + "_", y + "_", 1).replace(x + ".", y + ".", 1)
            elif x in name:
                return name.replace(x, y, 1)
    return None


def mirror_map(names):
    """(J,) int: for each joint its mirror's index, or itself when it has none."""
    index = {n: i for i, n in enumerate(names)}
    out = np.arange(len(names))
    for i, n in enumerate(names):
        m = mirror_name(n)
        if m is not None and m in index:
            out[i] = index[m]
    return out


def mirror_pose(pose, mirror, names, axis, source="L"):
    """Copy one side's local transforms onto the other, reflected across the plane normal to
    model ``axis`` (in place).

    Reflecting across the plane normal to x maps a rotation quaternion (x, y, z, w) to
    (x, -y, -z, w) (the component along the normal keeps its sign, the others flip) and a
    translation's x to -x. This is exact when the two sides' parent frames are mirror images
    aligned with the model axes: the usual case, and always so for frames built from head
    positions (elk skeletons, the bundled characters).
    """
    flip = np.ones(3)
    flip[axis] = -1.0
    qflip = -flip  # quaternion vector part under a reflection: -(sign) of each axis
    for i, name in enumerate(names):
        j = mirror[i]
        if j == i or _side_of(name) != source:
            continue
        pose.translation[j] = pose.translation[i] * flip
        q = pose.rotation[i].copy()
        q[:3] *= qflip
        pose.rotation[j] = q
        pose.scale[j] = pose.scale[i]


def _side_of(name):
    """"L", "R" or None from a joint name."""
    m = mirror_name(name)
    if m is None:
        return None
    for left, right in _MIRROR_PAIRS:
        if (left in name and right in m) and not (right in name and left in m):
            return "L"
        if right in name and left in m:
            return "R"
    return None


def side_axis(skeleton, mirror):
    """Index of the model axis that runs left-right: the one along which the rest positions
    of mirrored joint pairs differ most (0 when no joint has a mirror).

    Parameters
    ----------
    skeleton : Skeleton
    mirror : (J,) int
        :func:`mirror_map` of its names.
    """
    heads = skeleton.bind_matrices[:, :3, 3]
    pairs = np.flatnonzero(mirror != np.arange(len(mirror)))
    if len(pairs) == 0:
        return 0
    diff = np.abs(heads[pairs] - heads[mirror[pairs]]).sum(axis=0)
    return int(np.argmax(diff))
