"""glTF 2.0 out: a rig's :class:`~rigedit.io.data.RigData` -> ``.glb`` (binary) or ``.gltf``
(one JSON file with its buffer embedded as a data URI).

What is written: the mesh (one primitive per primitive that came in, or one for a rig without
surface data) with positions, normals (the file's, or area-weighted smooth normals), UVs and
materials with their textures as they came in; the skin with every joint and the skeleton's
inverse bind matrices; the joints as nodes with their local rest TRS; every clip as an
animation. Interpolation maps honestly: ``step`` -> STEP, ``linear``/``slerp`` -> LINEAR,
``catmull_rom`` -> CUBICSPLINE with its tangents (the same curve), ``cubic_spline`` ->
CUBICSPLINE, and ``nlerp``/``hybrid`` (which glTF cannot express) resampled: each key
interval is cut into pieces of at most :data:`RESAMPLE_DEGREES` so that LINEAR (slerp) between
the samples stays within about 1e-6 rad of the original curve. A clip's duration and loop flag
go into the animation's ``extras``, a joint's tail and deform flag into its node's, and are
read back by rigedit. Morph targets and weight tracks: :mod:`rigedit.io.gltf_write_morph`.
Rigid parts that came in (meshes under a joint node) go out as primitives of the one skinned
mesh, each vertex bound wholly to its joint, in bind space: the same placement at every
frame.

The container is written here rather than through pygltflib because the writer needs exact
control of padding and of which fields appear (the Khronos validator flags stray defaults).
The file is written atomically.
"""
from __future__ import annotations

import base64
import json
import struct
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..animation.track import Track
from ..errors import RigFileError
from .atomic import atomic_write
from .data import as_rig_data
from .gltf_bezier import bezier_keys
from .gltf_write_morph import mesh_morph_fields, primitive_targets, weights_sampler

__all__ = ["save_gltf", "RESAMPLE_DEGREES"]

#: Longest piece (degrees) of an nlerp/hybrid rotation interval when it is resampled.
RESAMPLE_DEGREES = 1.0
_FLOAT, _UBYTE, _USHORT, _UINT = 5126, 5121, 5123, 5125
_TYPES = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4", 16: "MAT4"}


class _Writer:
    def __init__(self):
        self.doc = {"asset": {"version": "2.0", "generator": "rigedit"}, "bufferViews": [],
                    "accessors": []}
        self.blob = bytearray()

    def view(self, data, stride=None, target=None):
        self.blob += bytes((-len(self.blob)) % 4)
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if stride:
            view["byteStride"] = stride
        if target:
            view["target"] = target
        self.blob += data
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, array, ctype=_FLOAT, vertex=False, target=None, minmax=False):
        """Add an (N, C) array as its own tightly packed buffer view and accessor."""
        dtype = {_FLOAT: "<f4", _UBYTE: "u1", _USHORT: "<u2", _UINT: "<u4"}[ctype]
        arr = np.ascontiguousarray(np.asarray(array).reshape(len(array), -1), dtype=dtype)
        width = arr.shape[1]
        # vertex attributes need a byteStride that is a multiple of 4 (pad byte VEC2/VEC3 rows)
        row = arr.itemsize * width
        stride = -(-row // 4) * 4 if vertex else None
        data = arr.tobytes()
        if vertex and stride != row:
            padded = np.zeros((len(arr), stride), np.uint8)
            padded[:, :row] = arr.view(np.uint8).reshape(len(arr), row)
            data = padded.tobytes()
        acc = {"bufferView": self.view(data, stride if vertex else None, target),
               "componentType": ctype, "count": len(arr), "type": _TYPES[width]}
        if minmax:
            acc["min"] = arr.min(axis=0).astype(float).tolist()
            acc["max"] = arr.max(axis=0).astype(float).tolist()
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def add(self, kind, item):
        self.doc.setdefault(kind, []).append(item)
        return len(self.doc[kind]) - 1


def _smooth_normals(vertices, faces):
    """(V, 3) area-weighted vertex normals (unit; +y where a vertex has no face)."""
    n = np.zeros_like(vertices)
    if len(faces):
        f = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]],
                     vertices[faces[:, 2]] - vertices[faces[:, 0]])
        for k in range(3):
            np.add.at(n, faces[:, k], f)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.where(length > 1e-20, n / np.where(length > 1e-20, length, 1), [0.0, 1.0, 0.0])


def _influences(rig):
    """(V, K) joint indices and float32-exact weights summing to 1, K = 4 or 8, no joint twice
    in a row, zero slots pointing at joint 0."""
    v = len(rig.vertices)
    k = rig.indices.shape[1]
    m = sp.csr_matrix((rig.weights.ravel(), (np.repeat(np.arange(v), k), rig.indices.ravel())),
                      shape=(v, len(rig.skeleton)))
    m.sum_duplicates()
    m.eliminate_zeros()
    counts = np.diff(m.indptr)
    width = 4 if counts.max(initial=0) <= 4 else 8
    if counts.max(initial=0) > 8:
        raise ValueError(f"expected at most 8 influences per vertex, got {counts.max()}")
    joints = np.zeros((v, width), np.int64)
    weights = np.zeros((v, width))
    rows = np.repeat(np.arange(v), counts)
    slot = np.arange(m.nnz) - np.repeat(m.indptr[:-1], counts)
    joints[rows, slot] = m.indices
    weights[rows, slot] = m.data
    order = np.argsort(-weights, axis=1, kind="stable")
    joints = np.take_along_axis(joints, order, axis=1)
    weights = np.take_along_axis(weights, order, axis=1).astype(np.float32)
    # make each float32 row sum to 1 as exactly as float32 allows: the rounding goes on the
    # largest weight
    weights[:, 0] += np.float32(1.0) - weights.sum(axis=1, dtype=np.float32)
    return joints, weights


def _mesh(w, rig):
    """The mesh and its materials; returns the mesh index or None (no vertices)."""
    verts, faces, surf = rig.vertices, rig.faces, rig.surface
    if len(verts) == 0:
        return None
    normals = surf.normals if surf is not None and surf.normals is not None else \
        _smooth_normals(verts, faces)
    uvs = surf.uvs if surf is not None else None
    if surf is not None and surf.vertex_primitive is not None and len(surf.vertex_primitive):
        prim_of, prim_mat = surf.vertex_primitive, surf.primitive_material
        materials = _materials(w, surf)
    else:
        prim_of, prim_mat, materials = np.zeros(len(verts), np.int32), np.array([-1]), []
    joints, weights = _influences(rig)
    jtype = _UBYTE if len(rig.skeleton) <= 256 else _USHORT
    face_prim = prim_of[faces[:, 0]] if len(faces) else np.zeros(0, np.int32)
    primitives = []
    for p in range(len(prim_mat)):
        sel = np.flatnonzero(prim_of == p)
        if len(sel) == 0:
            continue
        local = np.full(len(verts), -1, np.int64)
        local[sel] = np.arange(len(sel))
        tri = local[faces[face_prim == p]]
        if np.any(tri < 0):
            raise ValueError(f"primitive {p}: expected its faces to use its own vertices")
        attrs = {"POSITION": w.accessor(verts[sel], vertex=True, target=34962, minmax=True),
                 "NORMAL": w.accessor(normals[sel], vertex=True, target=34962)}
        if uvs is not None:
            attrs["TEXCOORD_0"] = w.accessor(uvs[sel], vertex=True, target=34962)
        for s in range(joints.shape[1] // 4):
            attrs[f"JOINTS_{s}"] = w.accessor(joints[sel, 4 * s:4 * s + 4], jtype, vertex=True,
                                              target=34962)
            attrs[f"WEIGHTS_{s}"] = w.accessor(weights[sel, 4 * s:4 * s + 4], vertex=True,
                                               target=34962)
        prim = {"attributes": attrs, "mode": 4}
        if rig.morphs is not None:
            prim["targets"] = primitive_targets(w, rig.morphs, sel)
        if len(tri):
            itype = _USHORT if len(sel) <= 65535 else _UINT
            prim["indices"] = w.accessor(tri.reshape(-1, 1), itype, target=34963)
        if prim_mat[p] >= 0:
            prim["material"] = materials[int(prim_mat[p])]
        primitives.append(prim)
    mesh = {"name": rig.name, "primitives": primitives}
    if rig.morphs is not None:
        mesh.update(mesh_morph_fields(rig.morphs))
    return w.add("meshes", mesh)


def _materials(w, surf):
    """Write the surface's materials; returns a list mapping its indices to the file's."""
    out = []
    for mat in surf.materials:
        pbr = {"baseColorFactor": [float(c) for c in mat.base_color],
               "metallicFactor": 0.0, "roughnessFactor": 1.0}
        if mat.image_bytes is not None and mat.mime in ("image/png", "image/jpeg"):
            image = w.add("images", {"bufferView": w.view(mat.image_bytes),
                                     "mimeType": mat.mime})
            pbr["baseColorTexture"] = {"index": w.add("textures", {"source": image})}
        entry = {"name": mat.name, "pbrMetallicRoughness": pbr}
        if mat.double_sided:
            entry["doubleSided"] = True
        if mat.alpha_mode in ("MASK", "BLEND"):
            entry["alphaMode"] = mat.alpha_mode
        out.append(w.add("materials", entry))
    return out


def _nodes(w, rig):
    """Joint nodes with their rest TRS; returns (joint node indices, scene root nodes)."""
    sk = rig.skeleton
    first = len(w.doc.setdefault("nodes", []))
    for j, name in enumerate(sk.names):
        node = {"name": name}
        t, r, s = sk.rest_translation[j], sk.rest_rotation[j], sk.rest_scale[j]
        if np.any(t != 0):
            node["translation"] = [float(x) for x in t]
        if np.any(r[:3] != 0) or r[3] != 1:
            node["rotation"] = [float(x) for x in r / np.linalg.norm(r)]
        if np.any(s != 1):
            node["scale"] = [float(x) for x in s]
        # what glTF has no field for, kept for rigedit: a bone's tail, a non-deforming joint
        extras = {}
        if np.all(np.isfinite(sk.tails[j])):
            extras["tail"] = [float(x) for x in sk.tails[j]]
        if not sk.deform[j]:
            extras["deform"] = False
        if extras:
            node["extras"] = {"rigedit": extras}
        kids = sk.children(j)
        if len(kids):
            node["children"] = [first + int(c) for c in kids]
        w.doc["nodes"].append(node)
    joints = list(range(first, first + len(sk)))
    roots = [first + int(j) for j in np.flatnonzero(sk.parents < 0)]
    if len(roots) > 1:  # one common root node (identity, not a joint) keeps the skin one tree
        roots = [w.add("nodes", {"name": f"{rig.name}_skeleton", "children": roots})]
    return joints, roots


def _key_times(tr):
    """Key times of an nlerp/hybrid rotation track cut so no piece turns more than
    RESAMPLE_DEGREES."""
    q = tr.values
    ang = 2 * np.arccos(np.clip(np.abs(np.sum(q[1:] * q[:-1], axis=1)), 0, 1))
    pieces = np.maximum(1, np.ceil(np.degrees(ang) / RESAMPLE_DEGREES)).astype(int)
    times = [np.linspace(a, b, n, endpoint=False) for a, b, n in
             zip(tr.times[:-1], tr.times[1:], pieces)]
    return np.concatenate(times + [tr.times[-1:]])


def _float32_times(times):
    """Key times as float32, each rounded down (never later than the key), so a STEP track
    read back still shows a key at exactly its time; kept strictly increasing."""
    t32 = np.asarray(times, dtype=np.float32)
    later = t32.astype(np.float64) > times
    t32[later] = np.nextafter(t32[later], np.float32(-np.inf))
    for i in range(1, len(t32)):
        if t32[i] <= t32[i - 1]:
            t32[i] = np.nextafter(t32[i - 1], np.float32(np.inf))
    return t32


def _track_sampler(w, tr):
    """(sampler dict) of one track, mapping its interpolation to glTF's."""
    mode, times = tr.interpolation, tr.times
    if mode == "bezier":   # CUBICSPLINE where exact, else resampled (io/gltf_bezier.py)
        times, values, kind = bezier_keys(tr)
    elif mode in ("nlerp", "hybrid") and len(times) > 1:
        times = _key_times(tr)
        values = np.array([tr.sample(t) for t in times])
        kind = "LINEAR"
    elif mode in ("catmull_rom", "cubic_spline") and len(times) > 1:
        tan = tr.tangents if mode == "cubic_spline" else np.repeat(tr.tangents[:, None], 2, 1)
        values = np.stack([tan[:, 0], tr.values, tan[:, 1]], axis=1).reshape(-1, tr.values.shape[1])
        kind = "CUBICSPLINE"
    else:
        values = tr.values
        kind = "STEP" if mode == "step" else "LINEAR"
    if tr.channel == "rotation" and kind != "CUBICSPLINE":
        values = values / np.linalg.norm(values, axis=1, keepdims=True)
    return {"input": w.accessor(_float32_times(times)[:, None], minmax=True),
            "output": w.accessor(values), "interpolation": kind}


def _weights_channel(w, rig, clip, mesh_node, samplers, channels):
    """Append the clip's morph weight channel (on the mesh node), if it has one."""
    got = None if rig.morphs is None or mesh_node is None else weights_sampler(clip, rig.morphs)
    if got is None:
        return
    times, out, mode = got
    samplers.append({"input": w.accessor(_float32_times(times)[:, None], minmax=True),
                     "output": w.accessor(out[:, None]), "interpolation": mode})
    channels.append({"sampler": len(samplers) - 1,
                     "target": {"node": mesh_node, "path": "weights"}})


def _animations(w, rig, joints, clips, mesh_node=None):
    names = list(rig.clips) if clips is None else list(clips)
    for name in names:
        if name not in rig.clips:
            raise KeyError(f"unknown clip {name!r} (the rig has {', '.join(rig.clips) or 'none'})")
    for name in names:
        clip_animation(w, rig, name, rig.clips[name], joints, mesh_node, _track_sampler)


def clip_animation(w, rig, name, clip, joints, mesh_node, sampler):
    """Add one clip's animation: a channel per track whose ``sampler(w, track)`` gives a
    sampler dict (None leaves the track out), the morph weights, duration and loop."""
    samplers, channels = [], []
    for (joint, channel), tr in clip.tracks.items():
        if np.any(tr.times < 0):
            raise ValueError(f"clip {name!r}: glTF key times must be >= 0, got "
                             f"{tr.times.min():g} on {joint!r} {channel}")
        got = sampler(w, tr)
        if got is None:
            continue
        samplers.append(got)
        channels.append({"sampler": len(samplers) - 1,
                         "target": {"node": joints[clip.skeleton.index[joint]],
                                    "path": channel}})
    _weights_channel(w, rig, clip, mesh_node, samplers, channels)
    if not channels:
        # a clip of no tracks (the rest pose held): a glTF animation needs a channel, one
        # without is dropped by readers and the clip would be lost; the root's rotation at
        # its rest over the clip's duration keeps it and its length
        sk = clip.skeleton
        times = [0.0, clip.duration] if clip.duration > 0 else [0.0]
        rest = Track("rotation", times, np.tile(sk.rest_rotation[0], (len(times), 1)), "slerp")
        samplers.append(sampler(w, rest))
        channels.append({"sampler": 0, "target": {"node": joints[0], "path": "rotation"}})
    if channels:
        w.add("animations", {"name": name, "samplers": samplers, "channels": channels,
                             "extras": {"rigedit": {"duration": clip.duration,
                                                    "loop": clip.loop}}})


def gltf_bytes(rig, binary=True, clips=None, compact=None):
    """The file's bytes: GLB when ``binary``, else glTF JSON with an embedded buffer; ``rig``
    is a :class:`~rigedit.io.data.RigData` (a Rig gives its ``data()``). ``compact``, a
    :class:`~rigedit.io.gltf_write_compact.CompactAnimations`, writes compressed clips instead
    of the rig's (and may rewrite the buffers, meshopt)."""
    rig = as_rig_data(rig)
    w = _Writer()
    mesh = _mesh(w, rig)
    joints, roots = _nodes(w, rig)
    ibm = rig.skeleton.inverse_bind_matrices.transpose(0, 2, 1).reshape(-1, 16)
    skin = {"joints": joints, "inverseBindMatrices": w.accessor(ibm)}
    if len(roots) == 1:
        skin["skeleton"] = roots[0]
    w.add("skins", skin)
    scene, mesh_node = list(roots), None
    if mesh is not None:  # at the scene root, no transform: the spec ignores it anyway
        mesh_node = w.add("nodes", {"name": rig.name, "mesh": mesh, "skin": 0})
        scene.insert(0, mesh_node)
    w.doc["scenes"] = [{"nodes": scene}]
    w.doc["scene"] = 0
    if compact is None:
        _animations(w, rig, joints, clips, mesh_node)
    else:
        compact.write(w, rig, joints, mesh_node)
    w.blob += bytes((-len(w.blob)) % 4)
    w.doc["buffers"] = [{"byteLength": len(w.blob)}]
    if compact is not None:
        compact.finish(w)
    if not binary:
        w.doc["buffers"][0]["uri"] = ("data:application/octet-stream;base64,"
                                      + base64.b64encode(bytes(w.blob)).decode("ascii"))
        return (json.dumps(w.doc, indent=1) + "\n").encode("utf-8")
    text = json.dumps(w.doc, separators=(",", ":")).encode("utf-8")
    text += b" " * ((-len(text)) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text
    body += struct.pack("<II", len(w.blob), 0x004E4942) + bytes(w.blob)
    return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body


def save_gltf(rig, path, clips=None, compact=None):
    """Write ``rig`` as glTF 2.0, atomically.

    Parameters
    ----------
    rig : RigData or Rig
        The rig's data (:class:`~rigedit.io.data.RigData`; a Rig gives its ``data()``).
    path : str or Path
        ``.glb`` (binary) or ``.gltf`` (JSON with the buffer embedded as a data URI).
    clips : list[str], optional
        Names of the clips to write; all when None.
    compact : CompactAnimations, optional
        Compressed clips to write instead (:mod:`rigedit.io.gltf_write_compact`).

    Raises
    ------
    RigFileError
        For another extension, an unknown clip or data glTF cannot hold (naming the file).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".glb", ".gltf"):
        raise RigFileError(path, f"expected a .glb or .gltf file name, got {suffix or 'none'!r}")
    try:
        data = gltf_bytes(rig, binary=suffix == ".glb", clips=clips, compact=compact)
    except (KeyError, ValueError) as exc:
        raise RigFileError(path, str(exc).strip("'\"")) from None
    with atomic_write(path, "wb", suffix=suffix) as fh:
        fh.write(data)
    return path
