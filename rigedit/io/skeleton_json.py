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
from .jsonfile import read_json, require

__all__ = ["load_skeleton", "save_skeleton", "skeleton_from_heads", "skeleton_to_dict"]


def _vec(path, joint, key, value, width):
    arr = np.asarray(value, dtype=object)
    try:
        out = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        out = None
    if out is None or out.shape != (width,) or not np.all(np.isfinite(out)):
        raise RigFileError(path, f"joint {joint!r}: expected {key!r} to be {width} numbers, "
                                 f"got {arr.tolist()!r}")
    return out


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
    hierarchy = data.get("hierarchy") if isinstance(data.get("hierarchy"), dict) else {}
    names, parents, heads, tails = [], [], [], []
    for i, j in enumerate(joints):
        name = require(path, j, "name", str, f" in joint {i}")
        names.append(name)
        # The joint's own "parent" wins; the file's {child: parent} map fills in when absent.
        parent = j["parent"] if "parent" in j else hierarchy.get(name)
        if parent is not None and not isinstance(parent, str):
            raise RigFileError(path, f"joint {name!r}: expected 'parent' to be a name or null, "
                                     f"got {parent!r}")
        parents.append(parent)
        heads.append(_vec(path, name, "head", require(path, j, "head", list, f" in joint {name!r}"), 3))
        tails.append(_vec(path, name, "tail", j["tail"], 3) if "tail" in j else [np.nan] * 3)
    heads, tails = np.array(heads), np.array(tails)
    # A zero-length bone (the elk's `_rootJoint` at the origin) only carries the rig: it
    # takes no weights, or the belly would be bound to a point on the ground.
    length = np.linalg.norm(tails - heads, axis=1)
    deform = ~(np.isfinite(length) & (length < 1e-9))
    try:
        return skeleton_from_heads(names, parents, heads, tails, deform)
    except ValueError as exc:
        raise RigFileError(path, str(exc)) from None


def _bind_matrix(path, joint, value):
    """(4, 4) float64 bind matrix of a joint (row-major nested lists), or None if absent."""
    if value is None:
        return None
    try:
        m = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        m = None
    if m is None or m.shape != (4, 4) or not np.all(np.isfinite(m)) \
            or not np.allclose(m[3], [0, 0, 0, 1]) or abs(np.linalg.det(m[:3, :3])) < 1e-12:
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


def _load_rigedit(path, data):
    joints = require(path, data, "joints", list)
    names, parents, t, r, s, tails, deform, binds = [], [], [], [], [], [], [], []
    for i, j in enumerate(joints):
        name = require(path, j, "name", str, f" in joint {i}")
        names.append(name)
        parents.append(j.get("parent"))
        t.append(_vec(path, name, "translation", j.get("translation", [0, 0, 0]), 3))
        r.append(_vec(path, name, "rotation", j.get("rotation", [0, 0, 0, 1]), 4))
        s.append(_vec(path, name, "scale", j.get("scale", [1, 1, 1]), 3))
        tails.append(_vec(path, name, "tail", j["tail"], 3) if "tail" in j else [np.nan] * 3)
        deform.append(bool(j.get("deform", True)))
        binds.append(_bind_matrix(path, name, j.get("bind_matrix")))
    try:
        order = topological_order(names, parents)
        pos = {names[k]: i for i, k in enumerate(order)}
        return Skeleton([names[k] for k in order],
                        [-1 if parents[k] in (None, "") else pos[parents[k]] for k in order],
                        np.array(t)[order], np.array(r)[order], np.array(s)[order],
                        tails=np.array(tails)[order], deform=np.array(deform)[order],
                        bind_matrices=_bind_pose(t, r, s, parents, names, binds, order))
    except ValueError as exc:
        raise RigFileError(path, str(exc)) from None


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
    if isinstance(joints[0], dict) and "head" in joints[0]:
        return _load_elk(path, data), {"format": "elk", "up": str(data.get("up", "z"))}
    return _load_rigedit(path, data), {"format": "rigedit", "up": str(data.get("up", "y"))}


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
