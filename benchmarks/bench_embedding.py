"""Skeleton embedding alone (``rigedit.embedding.embed_skeleton``): stage times and CD-J2J.

Run: ``.venv/bin/python benchmarks/bench_embedding.py [--repeat N]``

For each mesh, the wall seconds of every stage (best of N runs, default 1) and CD-J2J
(RigNet's chamfer distance between predicted and true joints, percent of the bounding-box
diagonal) where the truth is known:

- the bundled humanoid and quadruped on their own meshes (truth: their skeletons), with the
  template's mesh given (``template_mesh``, what ``rigedit.autorig`` passes for a bundled
  template) and without it (scale and ground estimated from the skeleton);
- the same characters skinned in other poses (A-pose, legs apart, crouch; head down,
  crouch), the rest template embedded in them (truth: the posed joints);
- the bundled characters' meshes stretched to other proportions (big head, short and long
  arms, arms close to the body, a thick body; a pug's short legs, a llama's long neck; see
  ``tests/test_embedding_stretch.py``), the rest template embedded (truth: the stretched
  pose's joints, all but the ground-level root);
- CesiumMan, RiggedFigure (``khronos-gltf``), Xbot (``threejs-characters``, Mixamo) with the
  humanoid template and the Quaternius horse (``quaternius-farm-animals``) with the
  quadruped's, skinned at rest (truth: the artist's joints mapped by the name tables of
  ``tests/test_embedding_stretch.py``, fingers and end markers left out, only those counted;
  and, column "all", RigNet's as the issue measures it: every template joint against every
  artist joint but fingers and end markers, no name table);
- bigger meshes: CesiumMan split twice at edge midpoints (41,154 vertices; same truth) and
  the bundled humanoid's mesh split once (99,990 vertices; same truth);
- speed only: ``cow.obj`` / ``homer.obj`` with the quadruped / humanoid templates.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

import rigedit  # noqa: E402
from rigedit.embedding import EmbeddingError, cd_j2j, embed_skeleton  # noqa: E402
from rigedit.io.mesh import load_mesh  # noqa: E402
from test_embedding import DATA, POSES, _posed, _subdivide  # noqa: E402
from test_embedding_stretch import (HUMAN, QUAD, SHARED, full_truth, shared_case,  # noqa: E402
                                    stretched, truth_joints)

STAGES = ("template", "distance field", "medial surface", "spheres", "graph", "search",
          "refinement", "placement")


def run(label, vertices, faces, template, truth=None, pick=None, repeat=1, with_mesh=True,
        everything=None):
    mesh = (template.vertices, template.faces) if with_mesh else None
    best = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        try:
            emb = embed_skeleton(vertices, faces, template.skeleton, template_mesh=mesh)
        except EmbeddingError as exc:
            print(f"{label:34s} {len(vertices):7d} refused: {exc}", flush=True)
            return
        total = time.perf_counter() - t0
        if best is None or total < best[0]:
            best = (total, emb)
    total, emb = best
    cd = ""
    if truth is not None:
        pred = emb.positions if pick is None else emb.positions[pick]
        cd = f"{cd_j2j(pred, truth, np.linalg.norm(np.ptp(vertices, axis=0))):5.2f}"
    full = ""
    if everything is not None:   # RigNet's: every template joint against the artist's
        full = f"{cd_j2j(emb.positions, everything, np.linalg.norm(np.ptp(vertices, axis=0))):5.2f}"
    stages = " ".join(f"{emb.seconds.get(s, 0.0):5.2f}" for s in STAGES)
    print(f"{label:34s} {len(vertices):7d} {cd:>6s} {full:>6s} {total:6.2f}  {stages}",
          flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=1)
    n = parser.parse_args().repeat
    human, quad = rigedit.load_rig("humanoid"), rigedit.load_rig("quadruped")
    rigs = {"humanoid": human, "quadruped": quad}
    print(f"{'mesh':34s} {'verts':>7s} {'CD %':>6s} {'all %':>6s} {'total':>6s}  "
          + " ".join(s.split()[0][:5] for s in STAGES))
    for rig in (human, quad):
        truth = rig.skeleton.bind_matrices[:, :3, 3]
        run(f"{rig.name} own mesh", rig.vertices, rig.faces, rig, truth, repeat=n)
        run(f"{rig.name} own mesh, no template mesh", rig.vertices, rig.faces, rig, truth,
            repeat=n, with_mesh=False)
        if rig is human:
            run(f"{rig.name} own mesh split once", *_subdivide(rig.vertices, rig.faces), rig,
                truth, repeat=n)
    for (which, pose), (angles, _) in POSES.items():
        rig = rigs[which]
        vertices, truth = _posed(rig, angles)
        run(f"{which} {pose}", vertices, rig.faces, rig, truth, repeat=n)
    for table, rig in ((HUMAN, human), (QUAD, quad)):
        pick = truth_joints(rig)
        for label, spec in table.items():
            vertices, truth = stretched(rig, *spec)
            run(f"{rig.name} {label}", vertices, rig.faces, rig, truth[pick], pick, repeat=n)
    if not DATA.is_dir():
        print(f"{DATA} is absent: the shared meshes are left out")
        return
    for path, (which, _) in SHARED.items():
        rig = rigs[which]
        vertices, faces, pick, truth = shared_case(path, rig)
        name = Path(path).name
        run(name, vertices, faces, rig, truth, pick, repeat=n, everything=full_truth(path))
        if name == "CesiumMan.glb":
            big_v, big_f = _subdivide(*_subdivide(vertices, faces))
            run(f"{name} split twice", big_v, big_f, rig, truth, pick, repeat=n)
    cow_v, cow_f = load_mesh(DATA / "common-3d-test-models" / "cow.obj")
    run("cow.obj (quadruped)", np.c_[-cow_v[:, 2], cow_v[:, 1], cow_v[:, 0]], cow_f, quad,
        repeat=n)
    homer_v, homer_f = load_mesh(DATA / "common-3d-test-models" / "homer.obj")
    run("homer.obj (humanoid)", homer_v, homer_f, human, repeat=n)


if __name__ == "__main__":
    main()
