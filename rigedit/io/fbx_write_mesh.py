"""FBX out: the mesh (geometry and its model), its normals, UVs, materials and textures.

The geometry holds the rest vertices in file units (``Vertices``), the triangles as
``PolygonVertexIndex`` (each polygon's last index written as ``-(i + 1)``), and layers:
normals per polygon vertex (``ByPolygonVertex``, ``Direct``: what every importer reads), UVs
per polygon vertex indexing the per-vertex UV list (``IndexToDirect``; FBX's v points up, so
``v = 1 - v`` of rigedit's glTF convention), and the material of each triangle (``ByPolygon``)
when the rig has materials. A material is a ``Phong`` ``Material`` with its base colour as
``DiffuseColor`` and its alpha as ``Opacity``; a base colour texture becomes a ``Texture``
on ``DiffuseColor`` whose ``Video`` embeds the image file (``Content``), so the ``.fbx`` is
the whole character (no file is written beside it).
"""
from __future__ import annotations

import re

import numpy as np

from ..model.skinning import vertex_normals
from .fbx_document import properties70
from .fbx_write_skin import add_model

__all__ = ["write_mesh"]

_EXTENSIONS = {"image/png": ".png", "image/jpeg": ".jpg"}


def _polygon_vertex_index(faces):
    """(3F,) int32: each triangle's indices, the last one as ``-(i + 1)``."""
    pvi = np.asarray(faces, dtype=np.int64).copy()
    pvi[:, 2] = -pvi[:, 2] - 1
    if len(pvi) and (pvi.max() >= 2 ** 31 or pvi.min() < -2 ** 31):
        raise ValueError("expected fewer than 2**31 vertices for FBX's int32 indices")
    return pvi.reshape(-1).astype(np.int32)


def _layer(geometry, kind, mapping, reference, name=""):
    node = geometry.add(kind, 0)
    node.add("Version", 101)
    node.add("Name", name)
    node.add("MappingInformationType", mapping)
    node.add("ReferenceInformationType", reference)
    return node


def _face_materials(data):
    """(F,) material slot of each triangle and the list of rigedit material indices (-1: a
    default material) in slot order; (None, []) when the rig has no materials."""
    surf = data.surface
    if surf is None or not surf.materials or surf.vertex_primitive is None \
            or not surf.num_primitives or not len(data.faces):
        return None, []
    prim_of = surf.vertex_primitive[data.faces[:, 0]]
    face_mat = surf.primitive_material[prim_of]
    used = sorted({int(m) for m in face_mat})
    slots = np.searchsorted(used, face_mat).astype(np.int32)
    return slots, used


def _safe(name):
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("._") or "texture"


def _material(scene, mat, model, stem, index):
    """One material connected to the mesh ``model`` (its slot order is the connection
    order), with its texture embedded."""
    if mat is None:
        uid, node = scene.add("Material", "default", "Material")
        color, alpha = (0.8, 0.8, 0.8), 1.0
    else:
        uid, node = scene.add("Material", mat.name, "Material")
        color, alpha = tuple(float(c) for c in mat.base_color[:3]), float(mat.base_color[3])
    node.add("Version", 102)
    node.add("ShadingModel", "phong")
    node.add("MultiLayer", 0)
    node.append(properties70(("DiffuseColor", "color", *color), ("DiffuseFactor", "number", 1.0),
                             ("TransparencyFactor", "number", 1.0 - alpha),
                             ("Opacity", "double", alpha),
                             ("SpecularFactor", "number", 0.0)))
    scene.connect(uid, model)
    if mat is not None and mat.image_bytes is not None and mat.mime in _EXTENSIONS:
        file_name = f"{_safe(stem)}_{index}_{_safe(mat.name)}{_EXTENSIONS[mat.mime]}"
        tex, t = scene.add("Texture", mat.name, "Texture")
        t.add("Type", "TextureVideoClip")
        t.add("Version", 202)
        t.add("TextureName", f"{mat.name}\x00\x01Texture")
        t.append(properties70(("UseMaterial", "bool", 1)))
        t.add("Media", f"{mat.name}\x00\x01Video")
        t.add("FileName", file_name)
        t.add("RelativeFilename", file_name)
        t.add("ModelUVTranslation", 0.0, 0.0)
        t.add("ModelUVScaling", 1.0, 1.0)
        t.add("Texture_Alpha_Source", "None")
        t.add("Cropping", 0, 0, 0, 0)
        video, v = scene.add("Video", mat.name, "Video", "Clip")
        v.add("Type", "Clip")
        v.append(properties70(("Path", "url", file_name), ("RelPath", "url", file_name)))
        v.add("UseMipMap", 0)
        v.add("Filename", file_name)
        v.add("RelativeFilename", file_name)
        v.add("Content", bytes(mat.image_bytes))
        scene.connect(tex, uid, "DiffuseColor")
        scene.connect(video, tex)


def write_mesh(scene, data, unit):
    """The mesh model at the scene root, its geometry and materials.

    Parameters
    ----------
    scene : rigedit.io.fbx_document.Scene
        The document written into.
    data : rigedit.io.data.RigData
        Its vertices (V, 3), faces (F, 3) and surface (normals, UVs, materials).
    unit : float
        File units per metre.

    Returns
    -------
    model, geometry : Int64
        The ids of the mesh's model and of its geometry.
    """
    faces = data.faces
    surf = data.surface
    geo, g = scene.add("Geometry", data.name, "Geometry", "Mesh")
    g.add("GeometryVersion", 124)
    g.add("Vertices", (data.vertices * unit).reshape(-1))
    g.add("PolygonVertexIndex", _polygon_vertex_index(faces))
    normals = surf.normals if surf is not None and surf.normals is not None else \
        vertex_normals(data.vertices, faces)
    layers = ["LayerElementNormal"]
    _layer(g, "LayerElementNormal", "ByPolygonVertex", "Direct").add(
        "Normals", np.asarray(normals, dtype=np.float64)[faces].reshape(-1))
    if surf is not None and surf.uvs is not None:
        uv = np.column_stack([surf.uvs[:, 0], 1.0 - surf.uvs[:, 1]])
        node = _layer(g, "LayerElementUV", "ByPolygonVertex", "IndexToDirect", "UVMap")
        node.add("UV", uv.reshape(-1))
        node.add("UVIndex", faces.reshape(-1).astype(np.int32))
        layers.append("LayerElementUV")
    slots, used = _face_materials(data)
    if slots is not None:
        _layer(g, "LayerElementMaterial", "ByPolygon", "IndexToDirect").add("Materials", slots)
        layers.append("LayerElementMaterial")
    layer = g.add("Layer", 0)
    layer.add("Version", 100)
    for kind in layers:
        entry = layer.add("LayerElement")
        entry.add("Type", kind)
        entry.add("TypedIndex", 0)
    model = add_model(scene, data.name, "Mesh", np.zeros(3), np.zeros(3), np.ones(3))
    scene.connect(model, 0)
    scene.connect(geo, model)
    for k, index in enumerate(used):
        _material(scene, surf.materials[index] if index >= 0 else None, model, data.name, k)
    return model, geo
