"""Read an FBX file with ufbx directly (not through rigedit's reader) and save what the FBX
out tests compare, as an .npz: ``python ufbx_probe.py FILE.fbx OUT.npz TIMES.json``.

Run in a child process because ufbx 0.0.5's Python binding crashes in the cyclic garbage
collector and at interpreter exit once wrappers of a scene and of its evaluated copies are
about (measured: a segfault "Garbage-collecting" in 3 of 3 runs of a dozen evaluations): the
child collects nothing (``gc.disable``), frees no wrapper (every one it fetches is kept in
:data:`KEEP`; freeing a scene before the wrappers of its parts crashes too) and leaves with
``os._exit`` after writing the file.

TIMES.json is ``{stack name: [seconds, ...]}``: the mesh skinned by ufbx
(``Scene.evaluate(..., evaluate_skinning=True)``) at each, in metres after ufbx's unit
conversion (``target_unit_meters=1``, applied to the geometry).
"""
import gc
import json
import os
import sys

import numpy as np
import ufbx

#: Every ufbx wrapper fetched, kept alive until the process ends.
KEEP = []


def kept(value):
    KEEP.append(value)
    return value


def _vec3(values):
    return np.array([(v.x, v.y, v.z) for v in values], dtype=np.float64).reshape(-1, 3)


def probe(path, times):
    scene = kept(ufbx.load_file(path, target_unit_meters=1.0,
                           space_conversion=ufbx.SpaceConversion.MODIFY_GEOMETRY))
    settings = kept(scene.settings)
    out = {"unit_meters": settings.unit_meters,
           "original_unit_meters": settings.original_unit_meters,
           "up_axis": int(kept(settings.axes).up)}
    bones = kept([n for n in kept(list(scene.nodes)) if kept(n.bone) is not None])
    out["bone_names"] = np.array([n.name for n in bones])
    parents = kept([kept(n.parent) for n in bones])
    out["bone_parents"] = np.array([p.name if p is not None and kept(p.bone) is not None
                                    else "" for p in parents])
    stacks = kept(list(scene.anim_stacks))
    out["stack_names"] = np.array([s.name for s in stacks])
    out["stack_spans"] = np.array([(s.time_begin, s.time_end) for s in stacks]).reshape(-1, 2)
    if len(scene.meshes):
        mesh = kept(scene.meshes[0])
        out["vertices"] = _vec3(kept(mesh.vertices))
        out["vertex_indices"] = np.array(list(kept(mesh.vertex_indices)), dtype=np.int64)
        if kept(mesh.vertex_uv).exists:
            uv = kept(mesh.vertex_uv)
            out["uv_values"] = np.array([(v.x, v.y) for v in kept(uv.values)])
            out["uv_indices"] = np.array(list(kept(uv.indices)), dtype=np.int64)
        out["material_names"] = np.array([m.name for m in kept(list(mesh.materials))])
        out["face_material"] = np.array(list(kept(mesh.face_material)), dtype=np.int64)
        contents = [t.content for t in kept(list(scene.textures))]
        out["texture_content"] = np.frombuffer(b"".join(contents), dtype=np.uint8)
        skins = kept(list(mesh.skin_deformers))
        clusters = kept(list(kept(skins[0].clusters))) if skins else []
        out["cluster_bones"] = np.array([kept(c.bone_node).name for c in clusters])
        vertices = [list(kept(c.vertices)) for c in clusters]
        weights = [list(kept(c.weights)) for c in clusters]
        out["cluster_sizes"] = np.array([len(v) for v in vertices], dtype=np.int64)
        out["cluster_vertices"] = np.array(sum(vertices, []), dtype=np.int64)
        out["cluster_weights"] = np.array(sum(weights, []), dtype=np.float64)
    for s, stack in enumerate(stacks):
        for k, t in enumerate(times.get(stack.name, [])):
            evaluated = kept(scene.evaluate(kept(stack.anim), float(t),
                                            evaluate_skinning=True))
            if len(kept(evaluated.meshes)):
                skinned = kept(kept(kept(evaluated.meshes[0]).skinned_position).values)
                out[f"skinned_{s}_{k}"] = _vec3(skinned)
            nodes = kept(list(evaluated.nodes))
            out[f"bones_{s}_{k}"] = np.array(
                [tuple(nodes[n.typed_id].node_to_world.c3) for n in bones]).reshape(-1, 3)
    return out


if __name__ == "__main__":
    gc.disable()
    with open(sys.argv[3]) as fh:
        wanted = json.load(fh)
    np.savez(sys.argv[2], **probe(sys.argv[1], wanted))
    sys.stdout.flush()
    os._exit(0)
