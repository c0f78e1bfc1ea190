"""Checks of a glTF document against the spec before anything is decoded or allocated.

:class:`~rigedit.io.gltf_data.GltfData` runs these on the parsed JSON, so every reader above
it (skeleton, meshes, clips) sees only documents whose accessors have the component types the
spec allows for their use, whose material indices exist and whose joints have invertible rest
transforms; each problem is one :class:`~rigedit.errors.RigFileError` naming the file.

The tables are the glTF 2.0 spec's (section 3.7.2.1, "Meshes: overview") widened by
``KHR_mesh_quantization``'s, which are accepted even when a file does not declare the extension
(exporters forget to, and such values decode the same); a type in neither table (an
UNSIGNED_INT POSITION, float JOINTS) is refused.
"""
from __future__ import annotations

import re

import numpy as np

from ..errors import RigFileError

__all__ = ["json_depth", "check_document", "MAX_JSON_DEPTH"]

#: Nesting deeper than this is refused (a glTF's deepest standard object is about 6 levels;
#: extras may nest further, but thousands of levels only serve to exhaust the stack of
#: whatever walks them next: pygltflib, a writer, a deep copy).
MAX_JSON_DEPTH = 100

F, B, UB, S, US, UI = 5126, 5120, 5121, 5122, 5123, 5125
#: (component type, normalized) pairs allowed per attribute and its types.
_PLAIN = {
    "POSITION": ({"VEC3"}, {(F, False)}),
    "NORMAL": ({"VEC3"}, {(F, False)}),
    "TANGENT": ({"VEC4"}, {(F, False)}),
    "TEXCOORD": ({"VEC2"}, {(F, False), (UB, True), (US, True)}),
    "COLOR": ({"VEC3", "VEC4"}, {(F, False), (UB, True), (US, True)}),
    "JOINTS": ({"VEC4"}, {(UB, False), (US, False)}),
    "WEIGHTS": ({"VEC4"}, {(F, False), (UB, True), (US, True)}),
}
_ALL_INTS = {(t, n) for t in (B, UB, S, US) for n in (False, True)}
#: What KHR_mesh_quantization adds.
_QUANTIZED = {
    "POSITION": _ALL_INTS,
    "NORMAL": {(B, True), (S, True)},
    "TANGENT": {(B, True), (S, True)},
    "TEXCOORD": _ALL_INTS,
}
#: Morph target attributes (displacements: signed types only under quantization).
_TARGET = {"POSITION": ({"VEC3"}, {(F, False)}), "NORMAL": ({"VEC3"}, {(F, False)}),
           "TANGENT": ({"VEC3"}, {(F, False)})}
_TARGET_QUANTIZED = {"POSITION": {(B, False), (B, True), (S, False), (S, True)},
                     "NORMAL": {(B, True), (S, True)}, "TANGENT": {(B, True), (S, True)}}
_SEMANTIC = re.compile(r"^(POSITION|NORMAL|TANGENT|(TEXCOORD|COLOR|JOINTS|WEIGHTS)_\d+)$")


def json_depth(value, limit=MAX_JSON_DEPTH):
    """The nesting depth of parsed JSON, walked without recursion; stops past ``limit``.

    Returns
    -------
    int
        The depth (a scalar is 0, ``[]`` is 1), or ``limit + 1`` when deeper than ``limit``.
    """
    stack, deepest = [(value, 0)], 0
    while stack:
        item, depth = stack.pop()
        if isinstance(item, (list, dict)):
            depth += 1
            if depth > limit:
                return limit + 1
            deepest = max(deepest, depth)
            stack.extend((v, depth) for v in (item.values() if isinstance(item, dict) else item))
    return deepest


def _is_index(value):
    return isinstance(value, int) and not isinstance(value, bool) and value >= 0


def _accessor_of(doc, index):
    accessors = doc.get("accessors") if isinstance(doc.get("accessors"), list) else []
    if _is_index(index) and index < len(accessors) and isinstance(accessors[index], dict):
        return accessors[index]
    return None  # a missing or bad index: the reader that follows it names it


def _allowed(name, plain, quantized):
    base = name.split("_")[0] if "_" in name and not name.startswith("_") else name
    if base not in plain:
        return None
    types, pairs = plain[base]
    return base, types, pairs | quantized.get(base, set())


def _check_attribute(path, doc, where, name, index, plain, quantized):
    if not _SEMANTIC.match(name):
        return  # an application attribute (_FOO) or one the spec leaves free
    rule = _allowed(name, plain, quantized)
    acc = _accessor_of(doc, index)
    if rule is None or acc is None:
        return
    base, types, pairs = rule
    ctype = acc.get("componentType")
    kind = (ctype if isinstance(ctype, int) else repr(ctype), acc.get("normalized") is True)
    if not isinstance(acc.get("type"), str) or acc.get("type") not in types or kind not in pairs:
        allowed = ", ".join(f"{t}{' normalized' if n else ''}" for t, n in sorted(pairs))
        raise RigFileError(path, f"{where} {name}: expected a {'/'.join(sorted(types))} "
                                 f"accessor of componentType {allowed}, got {acc.get('type')!r} "
                                 f"componentType {kind[0]!r}{' normalized' if kind[1] else ''}")


def _check_primitive(path, doc, where, prim, n_materials):
    if not isinstance(prim, dict):
        return
    material = prim.get("material")
    if material is not None and not (_is_index(material) and material < n_materials):
        expected = (f"a material index 0..{n_materials - 1}" if n_materials
                    else "no material (the file has none)")
        raise RigFileError(path, f"{where}: expected {expected}, got {material!r}")
    attributes = prim.get("attributes")
    for name, index in (attributes.items() if isinstance(attributes, dict) else ()):
        _check_attribute(path, doc, where, name, index, _PLAIN, _QUANTIZED)
    targets = prim.get("targets")
    for t, target in enumerate(targets if isinstance(targets, list) else ()):
        for name, index in (target.items() if isinstance(target, dict) else ()):
            _check_attribute(path, doc, f"{where} target {t}", name, index, _TARGET,
                             _TARGET_QUANTIZED)
    indices = _accessor_of(doc, prim.get("indices"))
    if indices is not None and (indices.get("type") != "SCALAR"
                                or indices.get("normalized") is True
                                or indices.get("componentType") not in (UB, US, UI)):
        raise RigFileError(path, f"{where}: expected indices of type SCALAR and componentType "
                                 f"5121, 5123 or 5125, got {indices.get('type')!r} "
                                 f"{indices.get('componentType')!r}")


def _check_meshes(path, doc):
    materials = doc.get("materials")
    n_materials = len(materials) if isinstance(materials, list) else 0
    meshes = doc.get("meshes")
    for m, mesh in enumerate(meshes if isinstance(meshes, list) else ()):
        prims = mesh.get("primitives") if isinstance(mesh, dict) else None
        for p, prim in enumerate(prims if isinstance(prims, list) else ()):
            _check_primitive(path, doc, f"mesh {m} primitive {p}", prim, n_materials)


def _joint_nodes(doc, nodes):
    """Indices of the nodes that are skin joints or an ancestor of one."""
    parent = {}
    for i, node in enumerate(nodes):
        children = node.get("children") if isinstance(node, dict) else None
        for c in (children if isinstance(children, list) else ()):
            if _is_index(c):
                parent.setdefault(c, i)
    out = set()
    skins = doc.get("skins")
    for skin in (skins if isinstance(skins, list) else ()):
        joints = skin.get("joints") if isinstance(skin, dict) else None
        for j in (joints if isinstance(joints, list) else ()):
            while _is_index(j) and j not in out and j < len(nodes):
                out.add(j)
                j = parent.get(j)
    return sorted(out)


def _numbers(value, n):
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        return None
    return arr if arr.shape == (n,) and np.all(np.isfinite(arr)) else None


def _check_joint_transforms(path, doc):
    """A joint (or an ancestor of one) with a zero scale or a singular matrix has no inverse
    bind and no rotation to decompose: refused here in one line."""
    nodes = doc.get("nodes")
    if not isinstance(nodes, list):
        return
    for i in _joint_nodes(doc, nodes):
        node = nodes[i]
        if not isinstance(node, dict):
            continue
        matrix = _numbers(node.get("matrix"), 16) if node.get("matrix") is not None else None
        if matrix is not None:
            det = np.linalg.det(matrix.reshape(4, 4)[:3, :3])
            scale = np.abs(matrix.reshape(4, 4)[:3, :3]).max()
            if not abs(det) > 1e-12 * max(scale, 1e-300) ** 3 or scale == 0:
                raise RigFileError(path, f"node {i}: expected an invertible joint matrix, got "
                                         f"one of determinant {det:.3g}")
        scale = _numbers(node.get("scale"), 3) if node.get("scale") is not None else None
        if scale is not None and np.any(scale == 0):
            raise RigFileError(path, f"node {i}: expected a joint scale without zeros, got "
                                     f"{scale.tolist()}")


def check_document(path, doc):
    """Run every check on the parsed glTF JSON ``doc`` of the file at ``path``.

    Raises
    ------
    RigFileError
        Nesting deeper than :data:`MAX_JSON_DEPTH`; an attribute, target or indices accessor
        of a component type or type the spec does not allow for it; a material index that is
        negative or beyond the file's materials; a joint with a zero scale or a singular
        matrix.
    """
    if json_depth(doc) > MAX_JSON_DEPTH:
        raise RigFileError(path, f"expected JSON nested at most {MAX_JSON_DEPTH} levels deep, "
                                 "got deeper nesting")
    _check_meshes(path, doc)
    _check_joint_transforms(path, doc)
