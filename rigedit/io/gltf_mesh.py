"""glTF 2.0 in: the primitives of the drawn mesh nodes (skinned or rigid), merged into one
mesh, with their materials and morph targets."""
from __future__ import annotations

import io
import warnings
from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from ..errors import RigFileError
from ..model.morph import MorphTargets
from ..surface import Material, Surface
from .gltf_morph import assemble_morphs, mesh_morph_block, read_targets

__all__ = ["read_mesh", "MeshData", "MeshPart", "triangles", "decode_image"]

#: glTF primitive modes that make triangles.
TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN = 4, 5, 6


@dataclass
class MeshData:
    """Merged mesh: ``vertices`` (V, 3), ``faces`` (F, 3) int64, ``joints`` (V, K) skeleton
    joint indices, ``weights`` (V, K) rows summing to 1, ``surface``, ``morphs`` (or None)
    and ``morph_nodes`` (mesh node -> its target names)."""

    vertices: np.ndarray
    faces: np.ndarray
    joints: np.ndarray
    weights: np.ndarray
    surface: Surface
    morphs: Optional[MorphTargets] = None
    morph_nodes: dict = field(default_factory=dict)


def triangles(indices, mode):
    """(F, 3) triangles of a primitive's index list for mode 4 (list), 5 (strip) or 6 (fan).

    Strips alternate winding so every triangle keeps the first one's orientation (the spec's
    ``{v_i, v_{i+(1+i%2)}, v_{i+(2-i%2)}}``); fans are ``{v_{i+1}, v_{i+2}, v_0}``. Degenerate
    triangles (two equal indices, as strip stitching makes) are dropped.
    """
    idx = np.asarray(indices, dtype=np.int64).reshape(-1)
    if mode == TRIANGLES:
        tri = idx[: len(idx) // 3 * 3].reshape(-1, 3)
    elif mode == TRIANGLE_STRIP:
        i = np.arange(max(len(idx) - 2, 0))
        odd = i % 2
        tri = np.stack([idx[i], idx[i + 1 + odd], idx[i + 2 - odd]], axis=1)
    elif mode == TRIANGLE_FAN:
        i = np.arange(max(len(idx) - 2, 0))
        tri = np.stack([idx[i + 1], idx[i + 2], np.full(len(i), idx[0] if len(idx) else 0)],
                       axis=1)
    else:
        raise ValueError(f"expected a triangle mode (4, 5, 6), got {mode}")
    keep = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])
    return tri[keep]


def decode_image(data, mime=None):
    """Decode image file bytes into an (H, W, 4) uint8 RGBA array (imageio)."""
    import imageio.v3 as iio

    img = np.asarray(iio.imread(io.BytesIO(data)))
    if img.dtype == np.uint16:
        img = (img >> 8).astype(np.uint8)
    elif img.dtype != np.uint8:
        img = np.clip(np.asarray(img, dtype=np.float64) * (255.0 if img.max() <= 1.0 else 1.0),
                      0, 255).astype(np.uint8)
    if img.ndim == 2:
        img = img[:, :, None]
    if img.shape[2] in (1, 2):
        img = np.concatenate([np.repeat(img[:, :, :1], 3, axis=2), img[:, :, 1:]], axis=2)
    if img.shape[2] == 3:
        img = np.concatenate([img, np.full(img.shape[:2] + (1,), 255, np.uint8)], axis=2)
    return np.ascontiguousarray(img[:, :, :4])


def _materials(data, warning):
    out = []
    for i, mat in enumerate(data.gltf.materials or []):
        pbr = mat.pbrMetallicRoughness
        color = np.ones(4)
        texture = image = mime = None
        if pbr is not None:
            if pbr.baseColorFactor is not None:
                color = np.asarray(pbr.baseColorFactor, dtype=np.float64).reshape(4)
            info = pbr.baseColorTexture
            if info is not None and info.index is not None:
                textures = data.gltf.textures or []
                if not 0 <= info.index < len(textures):
                    raise RigFileError(data.path, f"material {i}: expected a texture index "
                                                  f"below {len(textures)}, got {info.index}")
                source = textures[info.index].source
                if source is not None:
                    image, mime = data.image_bytes(source)
                    try:
                        texture = decode_image(image, mime)
                    except Exception as exc:  # imageio raises per plugin; the rig still loads
                        warnings.warn(f"{data.path}: material {i}: cannot decode its base colour "
                                      f"texture ({exc}); showing the colour factor", warning,
                                      stacklevel=4)
                        image = mime = None
        out.append(Material(name=mat.name or f"material_{i}", base_color=color,
                            texture=texture, image_bytes=image, mime=mime,
                            double_sided=bool(mat.doubleSided),
                            alpha_mode=mat.alphaMode or "OPAQUE"))
    return out


def _attr(data, attrs, name, where):
    index = getattr(attrs, name, None)
    return None if index is None else data.accessor(index, f"{where} {name}")


def _influences(data, attrs, n, num_joints, where):
    joints, weights = [], []
    for set_ in range(2):
        j = _attr(data, attrs, f"JOINTS_{set_}", where)
        w = _attr(data, attrs, f"WEIGHTS_{set_}", where)
        if j is None and w is None:
            continue
        if j is None or w is None or j.shape != (n, 4) or w.shape != (n, 4):
            raise RigFileError(data.path, f"{where}: expected JOINTS_{set_} and WEIGHTS_{set_} "
                                          f"as {n} VEC4 each, got "
                                          f"{None if j is None else j.shape} and "
                                          f"{None if w is None else w.shape}")
        if j.dtype.kind != "u":
            raise RigFileError(data.path, f"{where}: expected JOINTS_{set_} of unsigned byte "
                                          f"or short, got {j.dtype}")
        joints.append(j.astype(np.int64))
        weights.append(np.asarray(w, dtype=np.float64))
    if not joints:
        raise RigFileError(data.path, f"{where}: expected JOINTS_0 and WEIGHTS_0 on a "
                                      "primitive bound to a skin, got none")
    j, w = np.concatenate(joints, axis=1), np.concatenate(weights, axis=1)
    if not np.all(np.isfinite(w)) or np.any(w < 0):
        raise RigFileError(data.path, f"{where}: expected finite weights >= 0, got "
                                      "NaN or negative ones")
    bad = (j >= num_joints) & (w > 0)
    if bad.any():
        raise RigFileError(data.path, f"{where}: expected joint indices below the skin's "
                                      f"{num_joints} joints, got {int(j[bad].max())}")
    j[j >= num_joints] = 0  # unweighted slots may hold anything
    return j, w


@dataclass
class MeshPart:
    """One mesh node to merge.

    Attributes
    ----------
    node : int
    joint_map : (K,) int64
        Skin joint slot -> skeleton joint (a rigid part: its one joint).
    transform : (4, 4) array or None
        Applied to the vertices (normals, morph deltas) first: a rigid part's placement in
        bind space, a skin's shared-bind offset; None for none.
    skinned : bool
        False for a rigid part: every vertex bound wholly to ``joint_map[0]``.
    """

    node: int
    joint_map: np.ndarray
    transform: Optional[np.ndarray] = None
    skinned: bool = True


def _indices(data, prim, n, where):
    if prim.indices is None:
        return np.arange(n)
    idx = data.accessor(prim.indices, f"{where} indices")
    if idx.shape[1] != 1 or idx.dtype.kind != "u":
        raise RigFileError(data.path, f"{where}: expected unsigned SCALAR indices, "
                                      f"got {idx.dtype} of width {idx.shape[1]}")
    idx = idx[:, 0].astype(np.int64)
    if idx.size and idx.max() >= n:
        raise RigFileError(data.path, f"{where}: expected indices below {n} "
                                      f"vertices, got {idx.max()}")
    return idx


def _positions(data, prim, where):
    pos = _attr(data, prim.attributes, "POSITION", where)
    if pos is None or pos.shape[1] != 3:
        raise RigFileError(data.path, f"{where}: expected a VEC3 POSITION, got "
                                      f"{None if pos is None else pos.shape}")
    pos = pos.astype(np.float64)
    if not np.all(np.isfinite(pos)):
        raise RigFileError(data.path, f"{where}: expected finite POSITION values, got "
                                      "NaN or inf")
    return pos


def _place(m, pos, nrm, tri, deltas, ndeltas):
    """Apply the (4, 4) affine ``m``: points, normals (inverse transpose), deltas (linear
    part); a mirroring ``m`` reverses the winding so faces keep facing out."""
    lin = m[:3, :3]
    inv = np.linalg.inv(lin)
    pos = pos @ lin.T + m[:3, 3]
    nrm = None if nrm is None else nrm @ inv
    deltas = deltas @ lin.T
    ndeltas = None if ndeltas is None else ndeltas @ inv
    if np.linalg.det(lin) < 0:
        tri = tri[:, [0, 2, 1]]
    return pos, nrm, tri, deltas, ndeltas


def read_mesh(data, parts, warning):
    """Merge every triangle primitive of the mesh nodes ``parts``, in their order.

    Parameters
    ----------
    data : GltfData
    parts : list[MeshPart]
    warning : type
        Warning class for skipped parts.

    Returns
    -------
    MeshData
        ``joints`` are skeleton joints; ``morphs`` the merged morph targets.
    """
    meshes = data.gltf.meshes or []
    acc = {k: [] for k in ("verts", "faces", "joints", "weights", "normals", "uvs", "prim_of")}
    prim_mat, blocks, skipped, offset, unweighted = [], [], set(), 0, 0
    for part in parts:
        m = data.gltf.nodes[part.node].mesh
        if not 0 <= m < len(meshes):
            raise RigFileError(data.path, f"node {part.node}: expected a mesh index below "
                                          f"{len(meshes)}, got {m}")
        block = None
        for p, prim in enumerate(meshes[m].primitives or []):
            where = f"mesh {m} primitive {p}"
            mode = TRIANGLES if prim.mode is None else prim.mode
            if not isinstance(mode, int) or not 0 <= mode <= 6:
                raise RigFileError(data.path, f"{where}: expected a mode 0..6, got {mode!r}")
            if mode not in (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN):
                skipped.add(mode)
                continue
            pos = _positions(data, prim, where)
            n = len(pos)
            tri = triangles(_indices(data, prim, n, where), mode)
            if part.skinned:
                j, w = _influences(data, prim.attributes, n, len(part.joint_map), where)
                empty = w.sum(axis=1) <= 0   # bound to the skin's first joint (warned below)
                w[empty, 0], j[empty, 0] = 1.0, 0
                unweighted += int(empty.sum())
            else:
                j, w = np.zeros((n, 1), np.int64), np.ones((n, 1))
            nrm = _attr(data, prim.attributes, "NORMAL", where)
            nrm = None if nrm is None else nrm[:, :3].astype(np.float64)
            uv = _attr(data, prim.attributes, "TEXCOORD_0", where)
            deltas, ndeltas = read_targets(data, prim, n, where)
            if block is None:
                block = mesh_morph_block(data, part.node, len(deltas))
            elif len(deltas) != len(block.names):
                raise RigFileError(data.path, f"{where}: expected {len(block.names)} morph "
                                              f"targets as the mesh's first primitive, got "
                                              f"{len(deltas)}")
            if part.transform is not None:
                pos, nrm, tri, deltas, ndeltas = _place(part.transform, pos, nrm, tri, deltas,
                                                        ndeltas)
            block.rows.append((offset, deltas, ndeltas))
            for key, value in (("verts", pos), ("faces", tri + offset),
                               ("joints", part.joint_map[j]), ("weights", w), ("normals", nrm),
                               ("uvs", None if uv is None else uv[:, :2].astype(np.float64)),
                               ("prim_of", np.full(n, len(prim_mat), dtype=np.int32))):
                acc[key].append(value)
            prim_mat.append(-1 if prim.material is None else _material_index(data, prim, where))
            offset += n
        if block is not None:
            blocks.append(block)
    if skipped:
        warnings.warn(f"{data.path}: skipped primitives that are not triangles (modes "
                      f"{sorted(skipped)})", warning, stacklevel=3)
    if unweighted:
        warnings.warn(f"{data.path}: {unweighted} vertices have no skin weight; bound to "
                      "the skin's first joint", warning, stacklevel=3)
    mesh = _merge(data, acc["verts"], acc["faces"], acc["joints"], acc["weights"],
                  acc["normals"], acc["uvs"], acc["prim_of"], prim_mat, warning)
    try:
        mesh.morphs, mesh.morph_nodes = assemble_morphs(blocks, offset)
    except ValueError as exc:   # MorphTargets' own checks
        raise RigFileError(data.path, f"morph targets: {exc}") from None
    return mesh


def _material_index(data, prim, where):
    if not isinstance(prim.material, int) or prim.material < 0:
        raise RigFileError(data.path, f"{where}: expected a material index >= 0, got "
                                      f"{prim.material!r}")
    return int(prim.material)


def _pad(arrays, k):
    return np.concatenate([np.pad(a, ((0, 0), (0, k - a.shape[1]))) for a in arrays])


def _merge(data, verts, faces, joints, weights, normals, uvs, prim_of, prim_mat, warning):
    if not verts:
        return MeshData(np.zeros((0, 3)), np.zeros((0, 3), np.int64), np.zeros((0, 1), np.int64),
                        np.zeros((0, 1)), Surface(None, None, np.zeros(0, np.int32),
                                                  np.zeros(0, np.int64), _materials(data, warning)))
    k = max(a.shape[1] for a in joints)
    j, w = _pad(joints, k), _pad(weights, k)
    total = w.sum(axis=1)   # > 0: read_mesh bound unweighted rows
    w = w / total[:, None]
    nrm = None
    if all(n is not None for n in normals):
        nrm = np.concatenate(normals)
        length = np.linalg.norm(nrm, axis=1, keepdims=True)
        nrm = np.where(length > 0, nrm / np.where(length > 0, length, 1), nrm)
    uv = None
    if any(u is not None for u in uvs):
        uv = np.concatenate([np.zeros((len(v), 2)) if u is None else u for u, v in zip(uvs, verts)])
    materials = _materials(data, warning)
    for m in prim_mat:
        if m >= len(materials):
            raise RigFileError(data.path, f"expected material indices below {len(materials)}, "
                                          f"got {m}")
    surface = Surface(nrm, uv, np.concatenate(prim_of), np.array(prim_mat, dtype=np.int64),
                      materials)
    return MeshData(np.concatenate(verts), np.concatenate(faces).reshape(-1, 3), j, w, surface)
