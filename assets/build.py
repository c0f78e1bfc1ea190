"""Build the bundled characters (assets/quadruped, assets/humanoid) from code.

Run: ``.venv/bin/python assets/build.py [quadruped|humanoid ...]``. Deterministic: the shapes
are signed distance fields of primitives along the bones, meshed with VTK (flying edges,
Taubin smoothing, quadric decimation); weights come from the same primitives; clips are baked
from procedural motion with planar leg IK. Needs pyvista/vtk (build time only).
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))

from _build.character import build_character  # noqa: E402
from rigedit.io.rig_folder import save_rig_folder  # noqa: E402


def quadruped():
    from _build import quadruped as Q
    from _build.quadruped_clips import make_clips
    return build_character("quadruped", Q.joints(), Q.prims, Q.regions(), make_clips,
                           spacing=0.006, target_vertices=30000, weight_offset=0.03)


def humanoid():
    from _build import humanoid as Hm
    from _build.humanoid_clips import make_clips
    return build_character("humanoid", Hm.joints(), Hm.prims, Hm.regions(), make_clips,
                           spacing=0.005, target_vertices=25000, weight_offset=0.025)


BUILDERS = {"quadruped": quadruped, "humanoid": humanoid}


def main(argv):
    names = argv or list(BUILDERS)
    for name in names:
        t0 = time.time()
        rig = BUILDERS[name]()
        out = HERE / name
        # the folder is the build's: a clip removed from the build loses its file (rig.json
        # lists the clip files the previous build wrote)
        save_rig_folder(out, rig, allow_bundled=True)
        print(f"{name}: built in {time.time() - t0:.1f} s -> {out}")


if __name__ == "__main__":
    main(sys.argv[1:])
