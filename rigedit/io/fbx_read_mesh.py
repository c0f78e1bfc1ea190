"""FBX in: every skinned mesh of a scene, triangulated and merged into one, its influences and
the bind matrices of its clusters, and its materials.

A skinned vertex of FBX (ufbx's ``ufbx_get_skin_vertex_matrix``) is
``sum_c w_c * node_to_world(bone_c) @ geometry_to_bone_c @ v`` with ``v`` in the mesh's
geometry space. rigedit keeps one rest position per vertex and one inverse bind matrix per
joint, so each mesh's vertices are placed by the geometry-to-world matrix its clusters were
bound with (``M``, the first cluster's; FBX stores one per cluster, equal in the files
seen) and a joint's inverse bind matrix is ``geometry_to_bone @ inv(M)``: the product is the
file's own. A joint bound by several meshes with different inverse binds gets the first;
a warning says so, as it does for vertices with no weight.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import RigFileError
from ..surface import Material, Surface
from .fbx_read_scene import matrix_of
from .fbx_read_shapes import merge_shapes, mesh_shapes
from .gltf_mesh import decode_image
from .jsonfile import MAX_MAGNITUDE
from .paths import read_bytes

__all__ = ["read_skinned_meshes", "SkinnedMeshes", "MAX_INFLUENCES", "check_numbers"]

#: Influences kept per vertex (the largest, as the file orders them after ufbx's cleaning).
MAX_INFLUENCES = 8


@dataclass
class SkinnedMeshes:
    """The merged mesh: ``vertices`` (V, 3), ``faces`` (F, 3) int64, ``bones`` (V, K) typed
    ids of the bone nodes, ``weights`` (V, K) (zero where a vertex has fewer), ``surface``,
    ``inverse_bind`` (bone node typed id -> (4, 4)), ``unweighted`` (V,) bool, per
    vertex ``mesh_node`` (the typed id of the node holding its mesh), ``morphs``
    (:class:`~rigedit.model.morph.MorphTargets` of the blend shapes, or None) and
    ``channels`` (target name -> element ids of its blend shape channels)."""

    vertices: np.ndarray
    faces: np.ndarray
    bones: np.ndarray
    weights: np.ndarray
    surface: Surface
    inverse_bind: dict = field(default_factory=dict)
    unweighted: np.ndarray = None
    mesh_node: np.ndarray = None
    morphs: object = None
    channels: dict = field(default_factory=dict)


def triangulate(face_begin, face_count, corner_pos):
    """(T, 3) corner indices of faces triangulated: a triangle as it is, a quad cut along
    its shorter diagonal, a larger polygon as a fan from its first corner; points and lines
    dropped.

    Parameters
    ----------
    face_begin, face_count : (F,) int
        First corner and number of corners of each face.
    corner_pos : (C, 3) float
        Position of each corner (for the quads' diagonals).
    """
    out = []
    tri = face_count == 3
    b = face_begin[tri]
    out.append(np.stack([b, b + 1, b + 2], axis=1))
    quad = face_count == 4
    b = face_begin[quad]
    d02 = np.linalg.norm(corner_pos[b] - corner_pos[b + 2], axis=1)
    d13 = np.linalg.norm(corner_pos[b + 1] - corner_pos[b + 3], axis=1)
    cut = d02 <= d13
    out.append(np.where(cut[:, None], np.stack([b, b + 1, b + 2], 1), np.stack([b, b + 1, b + 3], 1)))
    out.append(np.where(cut[:, None], np.stack([b, b + 2, b + 3], 1), np.stack([b + 1, b + 2, b + 3], 1)))
    for n in np.unique(face_count[face_count > 4]):
        b = face_begin[face_count == n]
        for k in range(1, n - 1):
            out.append(np.stack([b, b + k, b + k + 1], axis=1))
    return np.concatenate(out).astype(np.int64) if out else np.zeros((0, 3), np.int64)


def check_numbers(path, what, values):
    """Finite and at most :data:`~rigedit.io.jsonfile.MAX_MAGNITUDE` in magnitude (in metres),
    as every reader's coordinates, so that skinning cannot overflow."""
    values = np.asarray(values)
    if not np.all(np.isfinite(values)):
        raise RigFileError(path, f"expected finite {what}, got NaN or inf")
    if values.size and np.abs(values).max() > MAX_MAGNITUDE:
        raise RigFileError(path, f"expected {what} of at most {MAX_MAGNITUDE:g} in magnitude, "
                                 f"got {np.abs(values).max():g}")


def _corner_attribute(attr, count, width):
    """(C, width) values of a ufbx vertex attribute per corner, or None when absent."""
    if not attr.exists:
        return None
    values = np.asarray(attr.values, dtype=np.float64).reshape(-1, width)
    index = np.asarray(attr.indices, dtype=np.int64)
    if len(index) != count or (len(index) and index.max() >= len(values)):
        return None
    return values[index]


def _influences(skin, num_points, path):
    """(P, K) bone typed ids and weights of a mesh's control points from its skin."""
    sv = np.array([tuple(v) for v in skin.vertices], dtype=np.float64).reshape(-1, 3)
    sw = np.array([tuple(w) for w in skin.weights], dtype=np.float64).reshape(-1, 2)
    clusters = skin.clusters
    bone_of = np.array([-1 if c.bone_node is None else c.bone_node.typed_id for c in clusters]
                       + [-1], dtype=np.int64)
    k = int(min(MAX_INFLUENCES, max(1, sv[:, 1].max() if len(sv) else 1)))
    bones = np.full((num_points, k), -1, np.int64)
    weights = np.zeros((num_points, k))
    if len(sv) != num_points:
        raise RigFileError(path, f"skin {skin.name!r}: expected weights for {num_points} "
                                 f"vertices, got {len(sv)}")
    begin, count = sv[:, 0].astype(np.int64), sv[:, 1].astype(np.int64)
    for slot in range(k):
        has = count > slot
        idx = begin[has] + slot
        cluster = sw[idx, 0].astype(np.int64)
        bones[has, slot] = bone_of[np.where(cluster < len(clusters), cluster, -1)]
        weights[has, slot] = sw[idx, 1]
    weights[bones < 0] = 0.0
    if not np.all(np.isfinite(weights)):
        raise RigFileError(path, f"skin {skin.name!r}: expected finite weights, got NaN or inf")
    return bones, weights


def _inverse_binds(skin, m, inverse_bind, conflicts):
    """Add each cluster's ``geometry_to_bone @ inv(m)`` to ``inverse_bind`` (first wins)."""
    inv_m = np.linalg.inv(m)
    for c in skin.clusters:
        if c.bone_node is None:
            continue
        ibm = matrix_of(c.geometry_to_bone) @ inv_m
        key = c.bone_node.typed_id
        if key in inverse_bind:
            if not np.allclose(inverse_bind[key], ibm, rtol=1e-6, atol=1e-6):
                conflicts.add(c.bone_node.name)
        else:
            inverse_bind[key] = ibm


def _mesh_parts(mesh, node, path, part_offset, material_index, warning):
    """One skinned mesh: per-vertex arrays (after splitting corners by normal, UV and part)
    and its triangles."""
    skin = mesh.skin_deformers[0]
    points = np.asarray(mesh.vertices, dtype=np.float64).reshape(-1, 3)
    check_numbers(path, f"vertex positions of mesh {mesh.name!r}", points)
    m = matrix_of(skin.clusters[0].geometry_to_world) if skin.clusters else \
        matrix_of(node.geometry_to_world)
    corner_point = np.asarray(mesh.vertex_indices, dtype=np.int64)
    if len(corner_point) and corner_point.max() >= len(points):
        raise RigFileError(path, f"mesh {mesh.name!r}: expected vertex indices below "
                                 f"{len(points)}, got {corner_point.max()}")
    faces = mesh.faces
    begin = np.array([f.index_begin for f in faces], dtype=np.int64)
    count = np.array([f.num_indices for f in faces], dtype=np.int64)
    face_mat = np.asarray(mesh.face_material, dtype=np.int64) if len(mesh.materials) else \
        np.zeros(len(faces), np.int64)
    corner_face = np.repeat(np.arange(len(faces)), count)
    corner_part = face_mat[corner_face] if len(face_mat) == len(faces) else \
        np.zeros(len(corner_point), np.int64)
    normals = _corner_attribute(mesh.vertex_normal, len(corner_point), 3)
    uvs = _corner_attribute(mesh.vertex_uv, len(corner_point), 2)
    key = [corner_point[:, None].astype(np.float64), corner_part[:, None].astype(np.float64)]
    key += [a for a in (normals, uvs) if a is not None]
    _, first, corner_vertex = np.unique(np.concatenate(key, axis=1), axis=0,
                                        return_index=True, return_inverse=True)
    corner_vertex = corner_vertex.reshape(-1)
    tris = triangulate(begin, count, points[corner_point])
    vp = corner_point[first]
    world = points[vp] @ m[:3, :3].T + m[:3, 3]
    bones, weights = _influences(skin, len(points), path)
    mats = [material_index(mt) for mt in mesh.materials] or [-1]
    part_of = corner_part[first]
    return dict(vertices=world, faces=corner_vertex[tris], bones=bones[vp],
                weights=weights[vp], normals=None if normals is None else
                _rotate_normals(normals[first], m),
                uvs=None if uvs is None else np.column_stack([uvs[first, 0],
                                                              1.0 - uvs[first, 1]]),
                part=part_of + part_offset, part_material=[mats[min(i, len(mats) - 1)]
                                                           for i in range(max(len(mats), 1))],
                m=m, skin=skin, shapes=mesh_shapes(mesh, m, vp, path, warning))


def _rotate_normals(normals, m):
    n = normals @ np.linalg.inv(m[:3, :3])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.where(length > 0, n / np.where(length > 0, length, 1), n)


def read_skinned_meshes(scene, path, warning):
    """Merge every skinned mesh of ``scene`` (a held ufbx scene).

    Returns
    -------
    SkinnedMeshes
        0 vertices when the scene has no skinned mesh.
    """
    materials, index_of = [], {}

    def material_index(mt):
        if mt.typed_id not in index_of:
            index_of[mt.typed_id] = len(materials)
            materials.append(_material(mt, path, warning))
        return index_of[mt.typed_id]

    parts, inverse_bind, conflicts, unskinned = [], {}, set(), []
    offset = part_offset = 0
    part_material = []
    for mesh in scene.meshes:
        if not mesh.skin_deformers or not mesh.instances:
            unskinned.append(mesh.name)
            continue
        node = mesh.instances[0]
        p = _mesh_parts(mesh, node, path, part_offset, material_index, warning)
        _inverse_binds(p["skin"], p["m"], inverse_bind, conflicts)
        p["faces"] = p["faces"] + offset
        p["mesh_node"] = np.full(len(p["vertices"]), node.typed_id, np.int64)
        offset += len(p["vertices"])
        part_offset += len(p["part_material"])
        part_material += p["part_material"]
        parts.append(p)
    if unskinned:
        warnings.warn(f"{path}: skipped {len(unskinned)} meshes without a skin "
                      f"({', '.join(repr(n) for n in unskinned[:4])})", warning, stacklevel=3)
    if conflicts:
        warnings.warn(f"{path}: {len(conflicts)} bones bound with different bind poses by "
                      f"different meshes (kept the first mesh's): "
                      f"{', '.join(sorted(conflicts)[:4])}", warning, stacklevel=3)
    return _merge(parts, inverse_bind, materials, part_material)


def _merge(parts, inverse_bind, materials, part_material):
    if not parts:
        z = np.zeros((0, 1))
        return SkinnedMeshes(np.zeros((0, 3)), np.zeros((0, 3), np.int64), z.astype(np.int64),
                             z, Surface(None, None, np.zeros(0, np.int32), np.zeros(0, np.int64),
                                        materials), inverse_bind, np.zeros(0, bool),
                             np.zeros(0, np.int64))
    k = max(p["bones"].shape[1] for p in parts)

    def pad(name, fill):
        return np.concatenate([np.pad(p[name], ((0, 0), (0, k - p[name].shape[1])),
                                      constant_values=fill) for p in parts])

    bones, weights = pad("bones", -1), pad("weights", 0.0)
    normals = None
    if all(p["normals"] is not None for p in parts):
        normals = np.concatenate([p["normals"] for p in parts])
    uvs = None
    if any(p["uvs"] is not None for p in parts):
        uvs = np.concatenate([np.zeros((len(p["vertices"]), 2)) if p["uvs"] is None
                              else p["uvs"] for p in parts])
    surface = Surface(normals, uvs, np.concatenate([p["part"] for p in parts]),
                      np.array(part_material, dtype=np.int64), materials)
    unweighted = weights.sum(axis=1) <= 0
    offsets = np.cumsum([0] + [len(p["vertices"]) for p in parts])
    morphs, channels = merge_shapes([p["shapes"] for p in parts], offsets[:-1], offsets[-1])
    return SkinnedMeshes(np.concatenate([p["vertices"] for p in parts]),
                         np.concatenate([p["faces"] for p in parts]).reshape(-1, 3),
                         bones, weights, surface, inverse_bind, unweighted,
                         np.concatenate([p["mesh_node"] for p in parts]), morphs, channels)


def _material(mt, path, warning):
    """A :class:`Material` of a ufbx material: its base colour and base colour texture."""
    base = mt.pbr.base_color
    color = np.array(tuple(base.value_vec4), dtype=np.float64) if base.has_value else np.ones(4)
    factor = mt.pbr.base_factor
    if factor.has_value:
        color[:3] *= float(factor.value_vec4[0])
    color = np.clip(np.nan_to_num(color, nan=1.0), 0.0, 1.0)
    color[3] = 1.0 if not np.isfinite(color[3]) or color[3] <= 0 else color[3]
    texture = image = mime = None
    tex = base.texture
    if tex is not None:
        image = _texture_bytes(tex, path, warning)
        if image is not None:
            mime = "image/png" if image[:8] == b"\x89PNG\r\n\x1a\n" else "image/jpeg"
            try:
                texture = decode_image(image, mime)
            except Exception as exc:  # imageio raises per plugin; the rig still loads
                warnings.warn(f"{path}: material {mt.name!r}: cannot decode its base colour "
                              f"texture ({exc}); showing the colour", warning, stacklevel=4)
                image = mime = None
    return Material(name=mt.name or "material", base_color=color, texture=texture,
                    image_bytes=image, mime=mime)


def _texture_bytes(tex, path, warning):
    """The image bytes of a texture: embedded, else the file beside the FBX file (its
    relative name, else its base name, in the FBX file's folder and never outside it)."""
    content = tex.content
    if content:
        return bytes(content)
    folder = Path(path).resolve().parent
    names = [tex.relative_filename, tex.filename]
    candidates = []
    for name in names:
        if not name:
            continue
        name = name.replace("\\", "/")
        candidates += [folder / name, folder / Path(name).name]
    for candidate in candidates:
        try:
            resolved = candidate.resolve()
        except (OSError, RuntimeError):
            continue
        if resolved.parent != folder and folder not in resolved.parents:
            continue
        if resolved.is_file():
            return read_bytes(resolved)
    warnings.warn(f"{path}: texture {tex.filename or tex.name!r} is neither embedded nor in "
                  f"the file's folder; showing the colour", warning, stacklevel=5)
    return None
