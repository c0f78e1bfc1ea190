"""Does Blender's glTF importer take rigedit's compressed glTF? (run by hand, not a test)

Imports each file with Blender's own glTF importer (its defaults), then prints per file the
armature's bone count, each action's name, frame range and F-curve count, and for each action
(on a fresh import of the file: Blender keeps, on a channel an action does not key, what the
action before left there) the world position of every bone's head at a few frames, written to
``OUT.npz`` so it can be compared with the same file's poses read another way:

    blender -b --python benchmarks/blender_compressed_import.py -- OUT.npz FILE.glb [...]

Keys of ``OUT.npz``: ``<file stem>/<action>/frames`` (n,) scene frames and
``<file stem>/<action>/heads`` (n, B, 3) in Blender's Z-up world (the importer's +Y up to +Z
turn), ``<file stem>/bones`` (B,) names. Measured with Blender 3.4.1 (Debian's package).
"""
import sys
from pathlib import Path

import numpy as np

np.bool = bool  # Blender 3.4's glTF importer still uses the alias NumPy 1.24 removed

import bpy  # noqa: E402  (only inside Blender)


def _import(path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    result = bpy.ops.import_scene.gltf(filepath=str(path))
    return result, next(o for o in bpy.context.scene.objects if o.type == "ARMATURE")


def main(argv):
    out, files = Path(argv[0]), [Path(a) for a in argv[1:]]
    saved = {}
    for path in files:
        result, arm = _import(path)
        bones = [b.name for b in arm.pose.bones]
        saved[f"{path.stem}/bones"] = np.array(bones)
        names = [a.name for a in bpy.data.actions]
        print(f"{path.name}: import {result}, {len(bones)} bones, {len(names)} actions")
        for name in names:
            # each action on a fresh import: a channel an action does not key keeps, in
            # Blender, whatever the action played before left there
            _, arm = _import(path)
            action = bpy.data.actions[name]
            start, end = (int(round(f)) for f in action.frame_range)
            print(f"  action {action.name}: frames {start}-{end}, {len(action.fcurves)} "
                  f"F-curves")
            arm.animation_data.action = action
            frames = np.unique(np.linspace(start, end, 5).round().astype(int))
            heads = []
            for f in frames:
                bpy.context.scene.frame_set(int(f))
                heads.append([list(arm.matrix_world @ b.head) for b in arm.pose.bones])
            saved[f"{path.stem}/{action.name}/frames"] = frames
            saved[f"{path.stem}/{action.name}/heads"] = np.array(heads)
    np.savez(out, **saved)


if __name__ == "__main__":
    main(sys.argv[sys.argv.index("--") + 1:])
