"""Skeleton JSON: rigedit's own format and the elk project's ``skeleton/skeleton.json``.

rigedit format::

    {"format": "rigedit.skeleton", "version": 1, "up": "y",
     "joints": [{"name": "Hips", "parent": null, "translation": [x, y, z],
                 "rotation": [x, y, z, w], "scale": [1, 1, 1],
                 "tail": [x, y, z], "deform": true}, ...]}

``translation``/``rotation``/``scale`` are the local rest transform (parent space); ``tail``
(optional) is the model-space end of the joint's bone; ``deform`` (optional, default true) says
whether the joint takes skin weights; ``bind_matrix`` (optional, 4x4 rows) is the model-space
matrix the mesh was bound at, written only when the bind pose differs from the rest pose's
forward kinematics (glTF files may bind elsewhere); a joint without one binds at its rest.

elk format: ``{"joints": [{"name", "index", "head", "tail", "parent"}], "bones", "hierarchy"}``
with world-space heads and tails (Z up) and axis-aligned joint frames, so a joint's bind matrix
is a translation to its head.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import RigFileError
from ..model.skeleton import Skeleton, topological_order
from .atomic import write_json
from .jsonfile import (MAX_MAGNITUDE, boolean, choice, name, numbers, optional, read_json,
                       require, vector)

__all__ = ["load_skeleton", "save_skeleton", "skeleton_from_heads", "skeleton_to_dict",
           "UP_AXES"]

#: The vertical axes a rig may declare.
UP_AXES = ("y", "z")


def _vec(path, joint, key, value, width):
    return vector(path, value, width, repr(key), where=f"joint {joint!r}")


def _parent(path, joint, value):
    # An empty string marks a root in some exports, as null does.
    if value is None or (isinstance(value, str) and not value):
        return None
    return name(path, value, "'parent'", where=f"joint {joint!r}", controls=True)


def _checked(path, build):
    """Build the skeleton; a structural problem (cycle, unknown parent) or a bind pose that is
    not finite (scales compounding down a long chain) becomes a ``RigFileError``."""
    try:
        skeleton = build()
    except ValueError as exc:
        raise RigFileError(path, str(exc)) from None
    big = np.abs(skeleton.bind_matrices[:, :3, 3]).max()
    if not (np.all(np.isfinite(skeleton.inverse_bind_matrices)) and big <= 100 * MAX_MAGNITUDE):
        raise RigFileError(path, "expected a bind pose of finite, invertible joint matrices, "
                                 "got overflowing or degenerate ones")
    return skeleton


def skeleton_from_heads(names, parent_names, heads, tails=None, deform=None):
    """Skeleton with axis-aligned joint frames from model-space joint positions.

    Parameters
    ----------
    names : list[str]
    parent_names : list[str or None]
    heads : (J, 3) float
        Model-space joint positions (the bind matrix of a joint is a translation there).
    tails : (J, 3) float, optional
    deform : (J,) bool, optional

    Returns
    -------
    skeleton : Skeleton, joints reordered parent-before-child when needed.
    """
    order = topological_order(names, parent_names)
    names = [names[i] for i in order]
    heads = np.asarray(heads, dtype=np.float64)[order]
    pos = {n: i for i, n in enumerate(names)}
    parents = np.array([-1 if parent_names[i] in (None, "") else pos[parent_names[i]]
                        for i in order])
    local = heads - np.where(parents[:, None] >= 0, heads[np.maximum(parents, 0)], 0.0)
    return Skeleton(names, parents, local,
                    tails=None if tails is None else np.asarray(tails, dtype=float)[order],
                    deform=None if deform is None else np.asarray(deform, dtype=bool)[order])


def _load_elk(path, data):
    joints = require(path, data, "joints", list)
    hierarchy = optional(data, "hierarchy", {})
    if not isinstance(hierarchy, dict):
        raise RigFileError(path, f"expected 'hierarchy' to be an object {{child: parent}}, got "
                                 f"{type(hierarchy).__name__}")
    names, parents, heads, tails = [], [], [], []
    for i, j in enumerate(joints):
        joint = name(path, require(path, j, "name", str, f" in joint {i}"), "'name'", where=f"joint {i}")
        names.append(joint)
        # The joint's own "parent" wins; the file's {child: parent} map fills in when absent.
        parents.append(_parent(path, joint, j["parent"] if "parent" in j
                               else hierarchy.get(joint)))
        heads.append(_vec(path, joint, "head", require(path, j, "head", list,
                                                       f" in joint {joint!r}"), 3))
        tails.append(_vec(path, joint, "tail", j["tail"], 3) if j.get("tail") is not None
                     else [np.nan] * 3)
    heads, tails = np.array(heads), np.array(tails)
    # A zero-length bone (the elk's `_rootJoint` at the origin) only carries the rig: it
    # takes no weights, or the belly would be bound to a point on the ground.
    length = np.linalg.norm(tails - heads, axis=1)
    deform = ~(np.isfinite(length) & (length < 1e-9))
    return _checked(path, lambda: skeleton_from_heads(names, parents, heads, tails, deform))


def _bind_matrix(path, joint, value):
    """(4, 4) float64 bind matrix of a joint (row-major nested lists), or None if absent."""
    if value is None:
        return None
    m = numbers(path, value, "'bind_matrix'", width=4, count=4, where=f"joint {joint!r}")
    if not np.allclose(m[3], [0, 0, 0, 1]) or abs(np.linalg.det(m[:3, :3])) < 1e-12:
        raise RigFileError(path, f"joint {joint!r}: expected 'bind_matrix' to be an invertible "
                                 f"affine 4x4 matrix (rows, last [0, 0, 0, 1]), got "
                                 f"{str(value)[:80]}")
    return m


def _bind_pose(t, r, s, parents, names, binds, order):
    """(J, 4, 4) bind matrices in ``order``: the file's where given, the rest pose's forward
    kinematics elsewhere; None when the file gives none."""
    if all(b is None for b in binds):
        return None
    pos = {names[k]: i for i, k in enumerate(order)}
    rest = Skeleton([names[k] for k in order],
                    [-1 if parents[k] is None else pos[parents[k]] for k in order],
                    np.array(t)[order], np.array(r)[order], np.array(s)[order]).bind_matrices
    return np.stack([rest[i] if binds[k] is None else binds[k] for i, k in enumerate(order)])


def _present(obj, key, default):
    """``obj[key]``, or ``default`` when the key is absent; a null stays null (an error for
    the checker: a joint whose translation is null is broken, not at the origin)."""
    return obj[key] if key in obj else default


def _load_rigedit(path, data):
    joints = require(path, data, "joints", list)
    names, parents, t, r, s, tails, deform, binds = [], [], [], [], [], [], [], []
    for i, j in enumerate(joints):
        joint = name(path, require(path, j, "name", str, f" in joint {i}"), "'name'",
                     where=f"joint {i}", controls=True)
        names.append(joint)
        parents.append(_parent(path, joint, j.get("parent")))
        t.append(_vec(path, joint, "translation", _present(j, "translation", [0, 0, 0]), 3))
        r.append(_vec(path, joint, "rotation", _present(j, "rotation", [0, 0, 0, 1]), 4))
        if np.linalg.norm(r[-1]) < 1e-6:
            raise RigFileError(path, f"joint {joint!r}: expected 'rotation' to be a unit "
                                     f"quaternion (x, y, z, w), got {r[-1].tolist()}")
        s.append(_vec(path, joint, "scale", _present(j, "scale", [1, 1, 1]), 3))
        if np.any(np.abs(s[-1]) < 1e-6):
            raise RigFileError(path, f"joint {joint!r}: expected 'scale' without a zero "
                                     f"component, got {s[-1].tolist()}")
        tails.append(_vec(path, joint, "tail", j["tail"], 3) if j.get("tail") is not None
                     else [np.nan] * 3)
        deform.append(boolean(path, optional(j, "deform", True), "'deform'",
                              where=f"joint {joint!r}"))
        binds.append(_bind_matrix(path, joint, j.get("bind_matrix")))
    if deform and not any(deform):
        raise RigFileError(path, "expected at least one joint that deforms, got every joint "
                                 "'deform': false (nothing could move the mesh)")

    def build():
        order = topological_order(names, parents)
        pos = {names[k]: i for i, k in enumerate(order)}
        return Skeleton([names[k] for k in order],
                        [-1 if parents[k] is None else pos[parents[k]] for k in order],
                        np.array(t)[order], np.array(r)[order], np.array(s)[order],
                        tails=np.array(tails)[order], deform=np.array(deform)[order],
                        bind_matrices=_bind_pose(t, r, s, parents, names, binds, order))

    return _checked(path, build)


def load_skeleton(path):
    """Read a skeleton JSON file in either format.

    Returns
    -------
    skeleton : Skeleton
    meta : dict
        ``{"format": "rigedit" | "elk", "up": "y" | "z"}``.
    """
    path = Path(path)
    data = read_json(path)
    if not isinstance(data, dict):
        raise RigFileError(path, f"expected a JSON object, got {type(data).__name__}")
    joints = require(path, data, "joints", list)
    if not joints:
        raise RigFileError(path, "expected at least one joint, got none")
    elk = isinstance(joints[0], dict) and "head" in joints[0]
    up = choice(path, optional(data, "up", "z" if elk else "y"), "'up'", UP_AXES)
    if elk:
        return _load_elk(path, data), {"format": "elk", "up": up}
    return _load_rigedit(path, data), {"format": "rigedit", "up": up}


def skeleton_to_dict(skeleton, up="y"):
    """rigedit-format dictionary of a skeleton."""
    joints = []
    # bind matrices are written only when the mesh was bound elsewhere than the rest pose
    # (glTF files may do that); the loader derives them from the rest pose otherwise
    rest = skeleton.forward(skeleton.rest_local_matrices())
    bind = not np.allclose(rest, skeleton.bind_matrices, rtol=0,
                           atol=1e-9 * max(1.0, np.abs(rest).max()))
    for j, name in enumerate(skeleton.names):
        p = skeleton.parents[j]
        entry = {"name": name, "parent": None if p < 0 else skeleton.names[p],
                 "translation": skeleton.rest_translation[j].round(9).tolist(),
                 "rotation": skeleton.rest_rotation[j].round(12).tolist(),
                 "scale": skeleton.rest_scale[j].round(9).tolist()}
        if np.all(np.isfinite(skeleton.tails[j])):
            entry["tail"] = skeleton.tails[j].round(9).tolist()
        if not skeleton.deform[j]:
            entry["deform"] = False
        if bind:
            entry["bind_matrix"] = skeleton.bind_matrices[j].tolist()
        joints.append(entry)
    return {"format": "rigedit.skeleton", "version": 1, "up": up, "joints": joints}


def save_skeleton(path, skeleton, up="y"):
    """Write a skeleton in rigedit's format, atomically."""
    write_json(path, skeleton_to_dict(skeleton, up))
