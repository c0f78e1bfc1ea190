"""FBX in: blend shapes as morph targets (:class:`rigedit.model.morph.MorphTargets`).

An FBX blend shape channel (``BlendShapeChannel``) moves the control points of its mesh by
its shape's offsets times its weight (``DeformPercent`` / 100), before the skin deforms
them, which is what a morph target is. Channels of one name on several meshes (a "Smile" on
the head and on the teeth) become one target, moving all of them. A channel with in-between
shapes (several shapes at increasing weights, a piecewise blend) keeps its full-weight shape
only; a warning says so. Offsets are in the mesh's geometry space and are placed by the same
matrix as its vertices (:mod:`rigedit.io.fbx_read_mesh`).
"""
from __future__ import annotations

import warnings

import numpy as np

from ..errors import RigFileError
from ..model.morph import MorphTargets

__all__ = ["mesh_shapes", "merge_shapes"]


def _point_offsets(shape, num_points, path):
    """(P, 3) position and normal offsets of a blend shape per control point."""
    rows = np.asarray(shape.offset_vertices, dtype=np.int64)
    pos = np.asarray(shape.position_offsets, dtype=np.float64).reshape(-1, 3)
    nrm = np.asarray(shape.normal_offsets, dtype=np.float64).reshape(-1, 3)
    if len(pos) != len(rows) or (len(rows) and (rows.min() < 0 or rows.max() >= num_points)):
        raise RigFileError(path, f"blend shape {shape.name!r}: expected offsets of vertices "
                                 f"below {num_points}, got {len(pos)} offsets of "
                                 f"{len(rows)} indices")
    if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(nrm))):
        raise RigFileError(path, f"blend shape {shape.name!r}: expected finite offsets, got "
                                 "NaN or inf")
    dp, dn = np.zeros((num_points, 3)), np.zeros((num_points, 3))
    dp[rows] = pos
    if len(nrm) == len(rows):
        dn[rows] = nrm
    return dp, dn


def mesh_shapes(mesh, m, point_of_vertex, path, warning):
    """The blend shape channels of one mesh, on its (split) vertices.

    Parameters
    ----------
    mesh : Held
        A ufbx mesh.
    m : (4, 4)
        The matrix that placed its vertices (geometry to model space).
    point_of_vertex : (Vm,) int
        The control point of each of its vertices.

    Returns
    -------
    list of (name, element_id, default_weight, (Vm, 3) deltas, (Vm, 3) normal deltas)
    """
    num_points = len(mesh.vertices)
    lin = m[:3, :3]
    normal_lin = np.linalg.inv(lin).T
    out, in_betweens = [], []
    for deformer in mesh.blend_deformers:
        for channel in deformer.channels:
            shape = channel.target_shape
            if shape is None:
                continue
            if len(channel.keyframes) > 1:
                in_betweens.append(channel.name)
            dp, dn = _point_offsets(shape, num_points, path)
            out.append((channel.name or shape.name or "shape", channel.element_id,
                        float(channel.weight), dp[point_of_vertex] @ lin.T,
                        dn[point_of_vertex] @ normal_lin.T))
    if in_betweens:
        warnings.warn(f"{path}: blend shape channels with in-between shapes keep only their "
                      f"full-weight shape: {', '.join(in_betweens[:4])}", warning, stacklevel=4)
    return out


def merge_shapes(per_mesh, offsets, num_vertices):
    """One :class:`MorphTargets` of every mesh's channels, merged by name.

    Parameters
    ----------
    per_mesh : list of lists
        :func:`mesh_shapes` of each merged mesh.
    offsets : list of int
        First merged vertex of each mesh.
    num_vertices : int

    Returns
    -------
    morphs : MorphTargets or None
        None when no mesh has a blend shape.
    channels : dict[str, list[int]]
        Target name -> element ids of its channels (for the weight curves).
    """
    names, channels, deltas, normals, weights = [], {}, {}, {}, {}
    for shapes, first in zip(per_mesh, offsets):
        for name, element, weight, dp, dn in shapes:
            if name not in channels:
                names.append(name)
                channels[name] = []
                deltas[name] = np.zeros((num_vertices, 3), np.float32)
                normals[name] = np.zeros((num_vertices, 3), np.float32)
                weights[name] = weight
            channels[name].append(element)
            deltas[name][first:first + len(dp)] += dp
            normals[name][first:first + len(dn)] += dn
    if not names:
        return None, {}
    morphs = MorphTargets(tuple(names), np.stack([deltas[n] for n in names]),
                          normal_deltas=np.stack([normals[n] for n in names]),
                          default_weights=np.array([weights[n] for n in names]))
    return morphs, channels
