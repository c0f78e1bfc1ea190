"""Auto-rigging: time of each stage, and joint placement (CD-J2J) through the whole pipeline.

Run: ``.venv/bin/python benchmarks/bench_autorig.py [--speed] [--accuracy]
[--orientations STEP]`` (speed and accuracy by default).

**Orientations** (``--orientations STEP``): each mesh below turned by every STEP-th of the
24 axis-aligned turns, the whole pipeline run with the orientation guessed (and searched):
recovered within 5 degrees and sure, flagged NOT SURE, or wrong but sure (a failure).

**Speed**: ``rigedit.autorig`` with heat weights and the template's clips on
- 50k-vertex meshes: the bundled humanoid's mesh (24,999 vertices) split once at edge
  midpoints (VTK's linear subdivision) and quadric-decimated back to about 50,000 vertices
  (pyvista ``decimate``); ``homer.obj`` (6,002 vertices) split twice and decimated the same
  way; each in its own frame, orientation guessed;
- ``cow.obj`` (quadruped template) and ``homer.obj`` (humanoid template) from
  ``../shared/data/common-3d-test-models``, orientation guessed.
Each stage's wall seconds are printed (load/check, orient, the embedding's own stages,
weights, clips, total).

**Accuracy**: CD-J2J (RigNet's symmetric chamfer distance between predicted and true joint
positions, as a percentage of the bounding-box diagonal, ``rigedit.embedding.cd_j2j``) for
the bundled characters' own meshes (truth: their shipped skeleton, every joint) and the
Khronos CesiumMan and RiggedFigure (skinned at their rest pose; truth: the artist's joints
that the name table of ``tests/test_embedding.py`` maps onto the humanoid template, only
those counted). Each mesh is run twice: in its own frame with the orientation guessed, and
turned (Z up, facing -X, times 100, moved) with the orientation guessed again, so the guess
is part of what is measured.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

import rigedit  # noqa: E402
from rigedit.embedding import cd_j2j  # noqa: E402
from rigedit.rigging.autorig.mesh_check import read_mesh  # noqa: E402
# the artists' joints that the humanoid template's joints map onto (the embedding tests')
from test_embedding import DATA, KHRONOS  # noqa: E402
from test_autorig_orient import TURNS  # noqa: E402  (the 24 axis turns)

# rigedit axis -> the turned input's: up is the input's +Z, forward its -X (left: -Y)
TURN = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
TURN_SCALE, TURN_SHIFT = 100.0, np.array([250.0, -40.0, 13.0])


def _stage_line(seconds):
    return ", ".join(f"{k} {v:.2f}" for k, v in seconds.items())


def _fifty_k(vertices, faces, times):
    """The mesh split ``times`` times at edge midpoints, quadric-decimated to ~50k vertices."""
    import pyvista as pv

    mesh = pv.PolyData(vertices, np.c_[np.full(len(faces), 3), faces])
    fine = mesh.subdivide(times, "linear")
    coarse = fine.decimate(1.0 - 50_000 / fine.n_points * 0.98)   # faces ~ 2 x points
    faces = coarse.faces.reshape(-1, 4)[:, 1:]
    return np.asarray(coarse.points, dtype=np.float64), faces, fine.n_points


def speed():
    human = rigedit.load_rig("humanoid")
    v, f, fine = _fifty_k(human.vertices, human.faces, 1)
    cases = [(f"bundled humanoid mesh, subdivided ({fine} v) and decimated to {len(v)} "
              "vertices", (v, f), "humanoid")]
    homer = DATA / "common-3d-test-models" / "homer.obj"
    if homer.is_file():
        v, f, fine = _fifty_k(*read_mesh(homer), 2)
        cases.append((f"homer.obj subdivided twice ({fine} v) and decimated to {len(v)} "
                      "vertices", (v, f), "humanoid"))
    for name, template in (("cow.obj", "quadruped"), ("homer.obj", "humanoid")):
        path = DATA / "common-3d-test-models" / name
        if path.is_file():
            cases.append((f"{name} ({len(read_mesh(path)[0])} vertices)", str(path), template))
    print("## Speed (seconds per stage, heat weights, template clips retargeted)")
    for what, mesh, template in cases:
        t0 = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                rig = rigedit.autorig(mesh, template=template)
        except ValueError as exc:
            print(f"- {what}, template {template}: FAILED after {time.perf_counter() - t0:.1f} "
                  f"s: {exc}")
            continue
        rep = rig.autorig_report
        print(f"- {what}, template {template}: total {rep.seconds['total']:.1f} s; "
              f"{rep.orientation.describe()}")
        print(f"  {_stage_line(rep.seconds)}")


def _truth_cases():
    """(label, vertices, faces, template, predicted joint names, truth positions)."""
    out = []
    for name in ("humanoid", "quadruped"):
        rig = rigedit.load_rig(name)
        sk = rig.skeleton
        out.append((f"bundled {name}", rig.vertices, rig.faces, name, list(sk.names),
                    sk.bind_matrices[:, :3, 3]))
    for file, table in KHRONOS.items():
        path = DATA / "khronos-gltf" / file
        if not path.is_file():
            continue
        rig = rigedit.load_rig(path)
        v = rig.skin(rig.rest_pose())
        rest = rig.skeleton.forward(rig.skeleton.rest_local_matrices())
        truth = np.array([rest[rig.skeleton.index[a], :3, 3] for a in table.values()])
        out.append((file, v, rig.faces, "humanoid", list(table), truth))
    return out


def accuracy():
    print("## CD-J2J (% of the bounding-box diagonal), whole pipeline, orientation guessed")
    print("| mesh | frame | orientation | joints counted | CD-J2J |")
    print("|---|---|---|---|---|")
    for label, v, f, template, names, truth in _truth_cases():
        for frame in ("own", "turned"):
            if frame == "own":
                verts, tv = v, truth
            else:
                verts = v @ TURN.T * TURN_SCALE + TURN_SHIFT
                tv = truth @ TURN.T * TURN_SCALE + TURN_SHIFT
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    rig = rigedit.autorig((verts, f), template=template, clips=False)
            except ValueError as exc:
                print(f"| {label} | {frame} | - | - | FAILED: {exc} |")
                continue
            rep = rig.autorig_report
            m = rep.transform
            truth_rig = tv @ m[:3, :3].T + m[:3, 3]
            pred = np.array([rig.skeleton.bind_matrices[rig.skeleton.index[n], :3, 3]
                             for n in names])
            diag = float(np.linalg.norm(np.ptp(rig.vertices, axis=0)))
            print(f"| {label} | {frame} | {rep.orientation.describe()} | {len(names)} | "
                  f"{cd_j2j(pred, truth_rig, diag):.2f}% |")


def orientations(step, only=None):
    """The whole pipeline (idw weights, no clips: the orientation search is what is timed)
    on each mesh turned by every ``step``-th of the 24 axis turns: the orientation
    recovered within 5 degrees, or flagged (not sure); a wrong one reported sure is a
    failure."""
    from rigedit.rigging.autorig.mesh_check import read_mesh as read

    meshes = []
    for name, template, up, fwd in (("humanoid", "humanoid", [0, 1, 0], [0, 0, 1]),
                                    ("quadruped", "quadruped", [0, 1, 0], [0, 0, 1]),
                                    ("homer.obj", "humanoid", [0, 1, 0], [0, 0, 1]),
                                    ("cow.obj", "quadruped", [0, 1, 0], [1, 0, 0])):
        if name in ("humanoid", "quadruped"):
            rig = rigedit.load_rig(name)
            meshes.append((f"bundled {name}", rig.vertices, rig.faces, template, up, fwd))
        else:
            path = DATA / "common-3d-test-models" / name
            if path.is_file():
                meshes.append((name, *read(path), template, up, fwd))
    for file in KHRONOS:
        path = DATA / "khronos-gltf" / file
        if path.is_file():
            rig = rigedit.load_rig(path)
            meshes.append((file, rig.skin(rig.rest_pose()), rig.faces, "humanoid", [0, 1, 0],
                           [0, 0, 1]))
    if only:
        meshes = [m for m in meshes if only in m[0]]
    turns = TURNS[::step]
    print(f"## Orientation search: {len(turns)} of the 24 axis turns per mesh")
    print("| mesh | turns | recovered and sure | flagged (not sure) | wrong but sure | "
          "seconds per run (median, max) |")
    print("|---|---|---|---|---|---|")
    for label, v, f, template, up, fwd in meshes:
        counts = {"ok": 0, "flagged": 0, "wrong": 0}
        times, wrong = [], []
        for m in turns:
            t0 = time.perf_counter()
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    rep = rigedit.autorig((v @ m.T, f), template=template, clips=False,
                                          weights="idw").autorig_report
            except ValueError as exc:
                counts["flagged"] += 1      # refused, with the reason: nothing silent
                wrong.append(f"refused: {exc}")
                continue
            times.append(time.perf_counter() - t0)
            o = rep.orientation
            off = max(np.degrees(np.arccos(np.clip(o.up @ (m @ up), -1, 1))),
                      np.degrees(np.arccos(np.clip(o.forward @ (m @ fwd), -1, 1))))
            if not rep.sure:
                counts["flagged"] += 1
            elif off <= 5.0:
                counts["ok"] += 1
            else:
                counts["wrong"] += 1
                wrong.append(f"{o.describe()} for up {(m @ up).tolist()}")
        print(f"| {label} | {len(turns)} | {counts['ok']} | {counts['flagged']} | "
              f"{counts['wrong']} | {np.median(times):.1f}, {max(times):.1f} |")
        for w in wrong:
            print(f"  - {label}: {w}")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--speed", action="store_true")
    p.add_argument("--accuracy", action="store_true")
    p.add_argument("--orientations", type=int, default=0, metavar="STEP",
                   help="the orientation search on every STEP-th axis turn (1: all 24)")
    p.add_argument("--only", default=None, metavar="TEXT",
                   help="--orientations on the meshes whose label holds TEXT only")
    args = p.parse_args()
    print(f"load average at start: {' '.join(f'{x:.1f}' for x in os.getloadavg())} "
          f"({os.cpu_count()} cores; other jobs share the machine)")
    if args.orientations:
        orientations(args.orientations, args.only)
    both = not (args.speed or args.accuracy or args.orientations)
    if args.speed or both:
        speed()
    if args.accuracy or both:
        accuracy()
    print(f"load average at end: {' '.join(f'{x:.1f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
