"""Blender's bone heat on a glTF character, saved for bench_weights_quality.py (run by hand).

A reference tool, not part of the project's tests (they must not need Blender). It imports
each file with Blender's glTF importer (its defaults, as a user gets them), strips every
skinned mesh of its vertex groups and armature modifier, parents it again with "With
Automatic Weights" (``ARMATURE_AUTO``: Blender's bone heat) and writes, per file, an ``.npz``
with each skinned mesh's vertices in the glTF's own mesh coordinates (Blender turns Y up into
Z up on import; this turns it back) and its weights by bone name:

    blender -b --python benchmarks/blender_bone_heat.py -- OUT_DIR FILE.glb [FILE.gltf ...]

Keys of ``OUT_DIR/<stem>.npz``: ``objects`` (names), and per object ``i``: ``v<i>`` (N, 3)
vertices, ``w<i>`` (N, B) weights, ``bones`` (B,) bone names (shared by all objects),
``unweighted<i>`` (N,) bool, where Blender's heat found no solution (the vertex has no
weight at all), plus ``seconds`` (the time Blender spent in the parenting).

Measured with Blender 3.4.1 (Debian's package), headless. Its glTF importer needs NumPy's
old ``np.bool`` alias, restored below.
"""
import sys
import time
from pathlib import Path

import numpy as np

np.bool = bool  # Blender 3.4's glTF importer still uses the alias NumPy 1.24 removed

import bpy  # noqa: E402  (only inside Blender)


def bone_heat(path, out_dir):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=str(path))
    arms = [o for o in bpy.context.scene.objects if o.type == "ARMATURE"]
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"
              and any(m.type == "ARMATURE" for m in o.modifiers)]
    if not arms or not meshes:
        print(f"{path}: no armature or no skinned mesh")
        return
    bones = sorted({b.name for a in arms for b in a.data.bones})
    col = {b: i for i, b in enumerate(bones)}
    out = {"objects": np.array([o.name for o in meshes]), "bones": np.array(bones)}
    seconds = 0.0
    for i, obj in enumerate(meshes):
        arm = next(m.object for m in obj.modifiers if m.type == "ARMATURE")
        for m in [m for m in obj.modifiers if m.type == "ARMATURE"]:
            obj.modifiers.remove(m)
        obj.vertex_groups.clear()
        bpy.ops.object.select_all(action="DESELECT")
        obj.select_set(True)
        arm.select_set(True)
        bpy.context.view_layer.objects.active = arm
        t = time.perf_counter()
        bpy.ops.object.parent_set(type="ARMATURE_AUTO")
        seconds += time.perf_counter() - t
        names = {g.index: g.name for g in obj.vertex_groups}
        n = len(obj.data.vertices)
        w = np.zeros((n, len(bones)))
        for v in obj.data.vertices:
            for g in v.groups:
                name = names.get(g.group)
                if name in col:
                    w[v.index, col[name]] += g.weight
        co = np.array([v.co[:] for v in obj.data.vertices]).reshape(-1, 3)
        out[f"v{i}"] = np.stack([co[:, 0], co[:, 2], -co[:, 1]], axis=1)  # Z up -> Y up
        out[f"w{i}"] = w
        out[f"unweighted{i}"] = w.sum(axis=1) <= 0
        print(f"{path.name}: {obj.name}: {n} vertices, {int((w.sum(axis=1) <= 0).sum())} "
              f"unweighted")
    out["seconds"] = np.array(seconds)
    np.savez_compressed(Path(out_dir) / f"{path.stem}.npz", **out)


def main(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if len(args) < 2:
        print(__doc__)
        return
    Path(args[0]).mkdir(parents=True, exist_ok=True)
    for f in args[1:]:
        bone_heat(Path(f), args[0])


main(sys.argv)
