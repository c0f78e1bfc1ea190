"""glTF 2.0 in: morph targets (each primitive's ``targets``, the mesh's ``weights`` and
``extras.targetNames``) -> one :class:`~rigedit.model.morph.MorphTargets` over the merged mesh.

Each mesh node with targets contributes its own targets (an instanced mesh's targets are
separate per node, as glTF animates weights per node). A target is named from
``mesh.extras.targetNames`` (the convention of Blender's and three.js's exporters),
``target_<i>`` where the file gives none; repeats across nodes become ``name.1``... Only
``POSITION`` and ``NORMAL`` deltas are kept (``TANGENT`` deltas are not: rigedit has no
tangents). A node's own ``weights`` (overriding the mesh's) is not read: pygltflib drops it.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import RigFileError
from ..model.morph import MorphTargets
from .gltf_skeleton import unique_names

__all__ = ["MorphBlock", "read_targets", "mesh_morph_block", "assemble_morphs"]


@dataclass
class MorphBlock:
    """The targets of one mesh node: ``names`` (T,), ``weights`` (T,) defaults, and per
    primitive read ``(first vertex row, (T, n, 3) deltas, (T, n, 3) normal deltas or None)``."""

    node: int
    names: list
    weights: np.ndarray
    rows: list = field(default_factory=list)


def _delta(data, target, name, n, where):
    index = getattr(target, name, None)
    if index is None:
        return None
    d = data.accessor(index, f"{where} {name}")
    if d.shape != (n, 3):
        raise RigFileError(data.path, f"{where}: expected {n} VEC3 {name} deltas, got "
                                      f"{d.shape}")
    d = np.asarray(d, dtype=np.float64)
    if not np.all(np.isfinite(d)):
        raise RigFileError(data.path, f"{where}: expected finite {name} deltas, got NaN or inf")
    return d


def read_targets(data, prim, n, where):
    """The morph targets of one primitive of ``n`` vertices.

    Returns
    -------
    deltas : (T, n, 3) float64
    normals : (T, n, 3) float64 or None
        None when no target has NORMAL deltas (zeros for the targets without).
    """
    targets = prim.targets or []
    if not isinstance(targets, list):
        raise RigFileError(data.path, f"{where}: expected 'targets' to be a list, got "
                                      f"{targets!r}")
    pos, nrm = [], []
    for t, target in enumerate(targets):
        here = f"{where} target {t}"
        p = _delta(data, target, "POSITION", n, here)
        pos.append(np.zeros((n, 3)) if p is None else p)
        nrm.append(_delta(data, target, "NORMAL", n, here))
    normals = None
    if any(x is not None for x in nrm):
        normals = np.array([np.zeros((n, 3)) if x is None else x for x in nrm])
    return np.array(pos).reshape(len(targets), n, 3), normals


def mesh_morph_block(data, node, count):
    """A :class:`MorphBlock` for mesh node ``node`` whose primitives have ``count`` targets:
    names from ``extras.targetNames``, defaults from ``mesh.weights``."""
    mesh_index = data.gltf.nodes[node].mesh
    mesh = data.gltf.meshes[mesh_index]
    names = mesh.extras.get("targetNames") if isinstance(mesh.extras, dict) else None
    if not (isinstance(names, list) and len(names) == count):
        names = [None] * count
    names = [x if isinstance(x, str) and x.strip() else f"target_{i}"
             for i, x in enumerate(names)]
    weights = np.zeros(count)
    if mesh.weights:   # pygltflib's default is []
        try:
            weights = np.asarray(mesh.weights, dtype=np.float64).reshape(count)
        except (TypeError, ValueError):
            raise RigFileError(data.path, f"mesh {mesh_index}: expected {count} morph weights, "
                                          f"got {mesh.weights!r}") from None
        if not np.all(np.isfinite(weights)):
            raise RigFileError(data.path, f"mesh {mesh_index}: expected finite morph weights, "
                                          "got NaN or inf")
    return MorphBlock(node, names, weights)


def assemble_morphs(blocks, n_vertices):
    """One MorphTargets over the merged mesh.

    Parameters
    ----------
    blocks : list[MorphBlock]
    n_vertices : int
        V of the merged mesh (rows no block covers get zero deltas).

    Returns
    -------
    morphs : MorphTargets or None
        None when no block has targets.
    morph_nodes : dict[int, list[str]]
        Mesh node -> the names of its targets, in the file's order (for weight channels).
    """
    blocks = [b for b in blocks if b.names]
    if not blocks:
        return None, {}
    names = unique_names([x for b in blocks for x in b.names])
    total = len(names)
    deltas = np.zeros((total, n_vertices, 3), dtype=np.float32)
    normals = None
    if any(nd is not None for b in blocks for _, _, nd in b.rows):
        normals = np.zeros_like(deltas)
    nodes, first = {}, 0
    for b in blocks:
        count = len(b.names)
        nodes[b.node] = names[first:first + count]
        for row, d, nd in b.rows:
            deltas[first:first + count, row:row + d.shape[1]] = d
            if nd is not None:
                normals[first:first + count, row:row + d.shape[1]] = nd
        first += count
    weights = np.concatenate([b.weights for b in blocks])
    return MorphTargets(tuple(names), deltas, normals, weights), nodes
