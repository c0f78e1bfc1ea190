"""Build one character: primitives -> mesh, skeleton, weights, clips -> rig folder."""
from __future__ import annotations

import numpy as np

from rigedit.io.skeleton_json import skeleton_from_heads
from rigedit.model.skeleton import topological_order
from rigedit.rig import Rig

from . import sdf
from .skin import primitive_weights


def build_character(name, joint_list, prims_fn, regions, clips_fn, spacing, target_vertices,
                    weight_offset, log=print):
    # Stored order is the skeleton's (depth-first, parent before child).
    order = topological_order([j[0] for j in joint_list], [j[1] for j in joint_list])
    joint_list = [joint_list[i] for i in order]
    names = [j[0] for j in joint_list]
    parents = [j[1] for j in joint_list]
    H = {j[0]: np.array(j[2], float) for j in joint_list}
    prims = prims_fn(H)
    verts, faces = sdf.mesh_from_prims([p for p in prims if p.role != "weights"], spacing,
                                       target_vertices)
    rep = sdf.edge_report(faces)
    if any(rep.values()):
        raise RuntimeError(f"{name}: mesh not closed/manifold/oriented: {rep}")
    # Weights in the modelling frame, before the mesh is set on the ground.
    indices, weights = primitive_weights(verts, [p for p in prims if p.role != "mesh"], names,
                                         regions, offset=weight_offset)
    # Stand on y = 0: lift everything but the ground-level root.
    dy = -verts[:, 1].min()
    verts = np.round(verts + [0, dy, 0], 6)
    lift = np.array([[0, 0 if p is None else dy, 0] for p in parents])
    heads = np.array([j[2] for j in joint_list], float) + lift
    tails = np.array([np.full(3, np.nan) if j[3] is None else j[3] for j in joint_list],
                     float) + lift
    deform = [j[4] for j in joint_list]
    skeleton = skeleton_from_heads(names, parents, heads, tails, deform)
    if skeleton.names != names:
        raise RuntimeError(f"{name}: joints must be listed parent-before-child")
    rig = Rig(skeleton, verts, faces, indices, weights, {}, name=name, up="y")
    rig.clips = clips_fn(skeleton)
    log(f"{name}: {len(verts)} vertices, {len(faces)} faces, {len(names)} joints, "
        f"clips {sorted(rig.clips)}, mesh lifted {dy * 1000:.1f} mm")
    return rig
