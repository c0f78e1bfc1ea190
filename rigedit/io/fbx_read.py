"""FBX in: a skinned FBX file (binary or ASCII, FBX 6.1 to 7.7) -> :class:`~rigedit.io.data.RigData`,
through the ``ufbx`` loader.

What is read
------------
- every skinned mesh, triangulated and merged into one, with normals, UVs, materials and
  base colour textures (embedded, or beside the file), the influences of its skin clusters
  (up to :data:`~rigedit.io.fbx_read_mesh.MAX_INFLUENCES` per vertex, the largest) and the
  clusters' bind poses (:mod:`rigedit.io.fbx_read_mesh`);
- the skeleton: the limb nodes and the clusters' bone nodes, parented as in the file. ufbx
  gives each node's local transform with its pre/post rotations, pivots, offsets and rotation
  order folded in (and non-standard scale inheritance compensated), so a joint's rest is that
  transform, exactly. A non-joint ancestor (an ``Armature`` node) that is a rotation, a uniform
  scale and a translation, and that no stack animates, is folded into the joints below it and
  their keys, as for glTF; any other becomes a non-deforming joint of its own;
- every animation stack as a clip (:mod:`rigedit.io.fbx_read_anim`);
- units and axes: ufbx converts the scene to metres, Y up, +Z forward (its
  ``target_unit_meters`` and ``target_axes``, applied to the geometry and transforms
  themselves); ``meta.notes["units"]`` and ``["frames"]`` say what the file had.

Blend shapes become morph targets with their channels' weight curves as weight tracks
(:mod:`rigedit.io.fbx_read_shapes`). Vertices a skin leaves without weight follow the node
holding their mesh (as FBX skinning does): that node then becomes a joint.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..errors import RigFileError
from ..model.skeleton import Skeleton, topological_order
from ..model.transforms import compose_trs, decompose_trs
from .data import RigData, RigMeta, build_rig
from .fbx_read_anim import animated_nodes, bake_stacks, clips_of
from .fbx_read_mesh import check_numbers, read_skinned_meshes
from .fbx_read_scene import axes_text, open_scene, release, ufbx_module
from .gltf_read import unique_names

__all__ = ["read_fbx", "load_fbx", "FbxWarning"]


class FbxWarning(UserWarning):
    """Something in an FBX file was skipped or guessed (the message says what)."""


def _similarity(m, tol=1e-6):
    """True when ``m``'s linear part is a uniform positive scale times a rotation."""
    lin = m[:3, :3]
    c = np.cbrt(np.linalg.det(lin))
    return bool(c > 1e-12 and np.allclose(lin.T @ lin, c * c * np.eye(3), atol=tol * c * c))


class _Nodes:
    """The scene's nodes as arrays: ``parent`` (N,) typed id or -1, ``local`` (N, 4, 4),
    ``trs`` (t, r, s) per node, ``names``, ``is_bone``, ``is_root``."""

    def __init__(self, scene):
        bone = int(ufbx_module().ElementType.BONE)
        nodes = scene.nodes
        self.nodes = nodes
        self.parent = np.array([-1 if n.parent is None else n.parent.typed_id for n in nodes],
                               dtype=np.int64)
        tr = [n.local_transform for n in nodes]
        self.t = np.array([tuple(x.translation) for x in tr], dtype=np.float64).reshape(-1, 3)
        self.r = np.array([tuple(x.rotation) for x in tr], dtype=np.float64).reshape(-1, 4)
        self.s = np.array([tuple(x.scale) for x in tr], dtype=np.float64).reshape(-1, 3)
        self.local = compose_trs(self.t, self.r, self.s) if len(nodes) else np.zeros((0, 4, 4))
        self.names = [n.name for n in nodes]
        self.is_bone = np.array([int(n.attrib_type) == bone for n in nodes], dtype=bool)
        self.is_root = np.array([bool(n.is_root) for n in nodes], dtype=bool)

    def rest(self, i):
        return {"translation": self.t[i], "rotation": self.r[i], "scale": self.s[i]}


def _members(nodes, wanted, moved):
    """Joints (typed ids, with the wanted first), each one's parent joint and its prefix.

    A non-wanted ancestor is folded into the prefix when it is a similarity no stack moves
    (the scene's root always is: ufbx converts into the nodes themselves), else it becomes a
    joint itself.
    """
    members, inside = list(wanted), set(wanted)
    for n in wanted:
        k = nodes.parent[n]
        while k >= 0:
            foldable = nodes.is_root[k] or (k not in moved and _similarity(nodes.local[k]))
            if k not in inside and not foldable:
                inside.add(k)
                members.append(k)
            k = nodes.parent[k]
    parent_of, prefix = {}, {}
    for n in members:
        p, chain = nodes.parent[n], []
        while p >= 0 and p not in inside:
            chain.append(p)
            p = nodes.parent[p]
        parent_of[n] = int(p) if p >= 0 else None
        pre = np.eye(4)
        for k in reversed(chain):
            pre = pre @ nodes.local[k]
        prefix[n] = None if np.allclose(pre, np.eye(4), atol=1e-12, rtol=0) else pre
    return members, parent_of, prefix


def _skeleton(path, nodes, mesh, moved):
    """The skeleton, ``joint_of_node`` (typed id -> joint) and each joint's prefix."""
    wanted = sorted(set(np.flatnonzero(nodes.is_bone & ~nodes.is_root).tolist())
                    | set(mesh.inverse_bind) | set(mesh.mesh_node[mesh.unweighted].tolist()))
    if not wanted:
        raise RigFileError(path, "expected a skeleton (limb nodes or skin clusters), got none")
    members, parent_of, prefix = _members(nodes, wanted, moved)
    raw = [nodes.names[n] if nodes.names[n].strip() else f"node_{n}" for n in members]
    name_of = dict(zip(members, unique_names(raw)))
    order = topological_order([name_of[n] for n in members],
                              [name_of.get(parent_of[n]) for n in members])
    ordered = [members[i] for i in order]
    joint_of = {n: j for j, n in enumerate(ordered)}
    t, r, s = [], [], []
    for n in ordered:
        if prefix[n] is None:
            t.append(nodes.t[n]), r.append(nodes.r[n]), s.append(nodes.s[n])
        else:
            tt, rr, ss = decompose_trs((prefix[n] @ nodes.local[n])[None])
            t.append(tt[0]), r.append(rr[0]), s.append(ss[0])
    parents = [-1 if parent_of[n] is None else joint_of[parent_of[n]] for n in ordered]
    # joints with a cluster deform; in a file without a skin (a skeleton and its motion, as
    # BVH gives) every joint does, so the rig can be retargeted from
    binds = set(mesh.inverse_bind) | set(mesh.mesh_node[mesh.unweighted].tolist())
    deform = np.array([n in binds or not binds for n in ordered])
    rest = Skeleton([name_of[n] for n in ordered], parents, np.array(t), np.array(r),
                    np.array(s), deform=deform)
    inverse = np.linalg.inv(rest.bind_matrices)
    for n, ibm in mesh.inverse_bind.items():
        inverse[joint_of[n]] = ibm
    try:
        bind = np.linalg.inv(inverse)
    except np.linalg.LinAlgError:
        raise RigFileError(path, "expected invertible cluster bind matrices, got a singular "
                                 "one") from None
    if not (np.all(np.isfinite(bind)) and np.all(np.isfinite(inverse))):
        raise RigFileError(path, "expected finite cluster bind matrices, got NaN or inf")
    try:
        skeleton = Skeleton(rest.names, rest.parents, rest.rest_translation,
                            rest.rest_rotation, rest.rest_scale, bind_matrices=bind,
                            deform=deform)
    except ValueError as exc:
        raise RigFileError(path, f"expected a valid skeleton, got {exc}") from None
    skeleton.inverse_bind_matrices = inverse   # the file's own, not inverted twice
    return skeleton, joint_of, [prefix[n] for n in ordered]


def _influences(mesh, joint_of, path):
    """(V, K) joint indices and weights; unweighted vertices bound to their mesh's node."""
    idx = np.zeros(mesh.bones.shape, np.int64)
    has = mesh.bones >= 0
    idx[has] = [joint_of[b] for b in mesh.bones[has]]
    weights = mesh.weights.copy()
    if mesh.unweighted.any():
        rows = np.flatnonzero(mesh.unweighted)
        idx[rows, 0] = [joint_of[n] for n in mesh.mesh_node[rows]]
        weights[rows, 0] = 1.0
        warnings.warn(f"{path}: {len(rows)} vertices have no skin weight; they follow the "
                      "node of their mesh", FbxWarning, stacklevel=4)
    if np.any(weights < 0):
        raise RigFileError(path, "expected skin weights >= 0, got negative ones")
    return idx, weights


def _notes(settings):
    unit = float(settings.original_unit_meters)
    axes = axes_text(settings.axes)
    named = {0.001: "millimetres", 0.01: "centimetres", 0.0254: "inches", 0.1: "decimetres",
             0.3048: "feet", 1.0: "metres", 1000.0: "kilometres"}
    name = next((v for k, v in named.items() if abs(unit - k) <= 1e-9 * k), f"{unit:g} m")
    units = (f"file in {name} (UnitScaleFactor {unit * 100:g}), converted to metres"
             if unit > 0 else "no unit stated; read as metres")
    frames = (f"file axes {axes}; converted to Y up, +Z forward" if axes !=
              "+X right, +Y up, +Z front" else "file axes +X right, +Y up, +Z front: "
              "rigedit's own, kept")
    return {"units": units, "frames": frames}, unit


def read_fbx(path):
    """Read a skinned FBX file (binary or ASCII), ``path`` (str or os.PathLike).

    Returns
    -------
    RigData
        In metres, Y up, with ``surface``, the file's influences and one clip per
        animation stack; ``meta.notes`` says how units and axes were converted.

    Raises
    ------
    RigFileError
        Naming the file and the problem: not FBX, truncated or corrupt (any ufbx error), an
        array claiming more than its bytes hold, no skeleton, NaN in the transforms.
    """
    path = Path(path)
    scene, keep = open_scene(path)
    try:
        return _read(scene, keep, path)
    except RigFileError as exc:
        # a new error: the old one's traceback holds the read's frames (and their ufbx
        # objects), which must not outlive release()
        error = RigFileError(exc.path, exc.problem)
    except (TypeError, ValueError, KeyError, IndexError, AttributeError,
            np.linalg.LinAlgError) as exc:
        error = RigFileError(path, f"expected a valid FBX scene, got one rigedit cannot use "
                                   f"({type(exc).__name__}: {exc})")
    finally:
        del scene
        release(keep)
    raise error


def load_fbx(path):
    """Read a skinned FBX file into a :class:`~rigedit.rig.Rig` (:func:`read_fbx`, then
    ``Rig.from_data``)."""
    return build_rig(read_fbx(path))


def _ufbx_warnings(scene, path):
    """One warning for what ufbx repaired while reading (indices out of range clamped, ...)."""
    counts = {}
    for w in scene.metadata.warnings:
        counts[w.description] = counts.get(w.description, 0) + max(1, int(w.count))
    if counts:
        kinds = "1 kind of problem" if len(counts) == 1 else f"{len(counts)} kinds of problem"
        warnings.warn(f"{path}: ufbx repaired {kinds} while reading: " + "; ".join(
            f"{d} ({n} times)" if n > 1 else d for d, n in list(counts.items())[:4]),
            FbxWarning, stacklevel=4)


def _read(scene, keep, path):
    _ufbx_warnings(scene, path)
    settings = scene.settings
    fps = float(settings.frames_per_second)
    fps = fps if np.isfinite(fps) and 1.0 <= fps <= 1000.0 else 30.0
    nodes = _Nodes(scene)
    for what, arr in (("translation", nodes.t), ("rotation", nodes.r), ("scale", nodes.s)):
        check_numbers(path, f"node {what}s", arr)
    mesh = read_skinned_meshes(scene, path, FbxWarning)
    check_numbers(path, "vertex positions", mesh.vertices)
    for ibm in mesh.inverse_bind.values():
        check_numbers(path, "cluster bind matrices", ibm)
    stacks = bake_stacks(scene, keep, fps, path)
    moved = animated_nodes(stacks, {i: nodes.rest(i) for i in range(len(nodes.names))})
    skeleton, joint_of, prefix = _skeleton(path, nodes, mesh, moved)
    indices, weights = (_influences(mesh, joint_of, path) if len(mesh.vertices) else
                        (np.zeros((0, 1), np.int64), np.zeros((0, 1))))   # no mesh, as BVH
    clips, shifts = clips_of(stacks, skeleton, joint_of, prefix, mesh.channels)
    notes, unit = _notes(settings)
    notes["frames"] += f"; clips baked at {fps:g} frames per second"
    if shifts:
        notes["frames"] += "; starting before 0 s, so keys shifted by " + ", ".join(
            f"{shift:.9g} s in {name!r}" for name, shift in shifts.items())
    return RigData(skeleton, mesh.vertices, mesh.faces, indices, weights, clips,
                   surface=mesh.surface if len(mesh.vertices) else None, name=path.stem,
                   up="y", meta=RigMeta(source=path, format="fbx", units="metres",
                                        scale=unit if unit > 0 else None, notes=notes),
                   morphs=mesh.morphs)
