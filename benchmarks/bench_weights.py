"""Speed and memory of the automatic weights (heat and idw).

Cases: a tube swept along a bent chain of 40 bones at 10k and 100k vertices (the sizes of
the issue's targets: 0.3 s and 4 s; Blender 3.4 took 1.1 s and 20.8 s on the same sizes),
and the bundled quadruped (30k vertices, 40 joints). Each case runs in a fresh process
(so peak RSS is that case's), once to warm up (numba's cached kernels load, CHOLMOD
initialises), then ``--repeat`` times; prints the best, median and worst wall-clock total, the
least CPU time (process time: all threads, so it can exceed the wall time), the peak RSS and
the best time of each stage (the machine is shared, so the best is the figure to compare).

    .venv/bin/python benchmarks/bench_weights.py [--repeat N] [--solver auto|splu|cholmod]
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
import warnings

import numpy as np

STAGES = ["weld", "laplacian", "distances", "visibility", "setup", "factorisation", "solve",
          "finish"]


def chain_tube(n_vertices, bones=40, segments=None):
    """A closed tube around a chain of ``bones`` bones bent into an S curve.

    Returns
    -------
    skeleton : Skeleton
    vertices : (V, 3) float64
    faces : (F, 3) int64
    """
    from rigedit.model import Skeleton
    segments = segments or max(12, int(np.sqrt(n_vertices / 8)))
    rings = max(2, n_vertices // segments)
    s = np.linspace(0.0, 1.0, bones + 1)
    heads = np.stack([0.3 * np.sin(2 * np.pi * s), 4.0 * s, 0.2 * np.sin(np.pi * s)], 1)
    u = np.linspace(0.0, 1.0, rings)
    centre = np.stack([0.3 * np.sin(2 * np.pi * u), 4.0 * u, 0.2 * np.sin(np.pi * u)], 1)
    tangent = np.gradient(centre, axis=0)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    side = np.cross(tangent, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side, axis=1, keepdims=True)
    up = np.cross(side, tangent)
    radius = 0.12 + 0.04 * np.sin(6 * np.pi * u)
    ang = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    ring = (np.cos(ang)[None, :, None] * side[:, None] + np.sin(ang)[None, :, None] * up[:, None])
    verts = (centre[:, None] + radius[:, None, None] * ring).reshape(-1, 3)
    r = np.arange(rings - 1)[:, None]
    k = np.arange(segments)[None, :]
    a, b = r * segments + k, r * segments + (k + 1) % segments
    c, d = a + segments, b + segments
    faces = np.concatenate([np.stack([a, b, d], -1).reshape(-1, 3),
                            np.stack([a, d, c], -1).reshape(-1, 3)])
    n = len(verts)
    caps = np.array([centre[0], centre[-1]])
    ring0, ring1 = np.arange(segments), (rings - 1) * segments + np.arange(segments)
    cap_faces = np.concatenate([
        np.stack([np.full(segments, n), np.roll(ring0, -1), ring0], 1),
        np.stack([np.full(segments, n + 1), ring1, np.roll(ring1, -1)], 1)])
    verts = np.concatenate([verts, caps])
    faces = np.concatenate([faces, cap_faces])
    names = [f"b{i}" for i in range(bones + 1)]
    local = np.diff(np.vstack([[0, 0, 0], heads]), axis=0)
    tails = np.full((bones + 1, 3), np.nan)
    sk = Skeleton(names, np.arange(bones + 1) - 1, local, tails=tails)
    return sk, verts, faces.astype(np.int64)


def case(name):
    if name == "quadruped":
        import rigedit
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rig = rigedit.load_rig("quadruped")
        return rig.skeleton, rig.vertices, rig.faces
    return chain_tube(int(name))


def child(name, method, repeat, solver):
    """Run one case in this process; print one JSON line."""
    from rigedit.binding.weights import compute_weights
    sk, verts, faces = case(name)
    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    options = {"solver": solver} if method == "heat" else {}
    totals, cpu, stages = [], [], {}
    for i in range(repeat + 1):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            t, c = time.perf_counter(), time.process_time()
            res = compute_weights(verts, sk, method, faces=faces, **options)
            dt, dc = time.perf_counter() - t, time.process_time() - c
        if i == 0:
            continue  # warm-up: loads the compiled kernels from numba's disk cache
        totals.append(dt)
        cpu.append(dc)
        for k, v in getattr(res, "timings", {}).items():
            stages[k] = min(stages.get(k, np.inf), v)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(json.dumps({"case": name, "method": method, "vertices": len(verts),
                      "joints": len(sk), "totals": totals, "cpu": cpu, "stages": stages,
                      "peak_mb": peak / 1024, "base_mb": base / 1024,
                      "fallback": len(getattr(res, "fallback", ()))}))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--solver", default="auto")
    ap.add_argument("--child", nargs=2)
    ap.add_argument("--cases", default="10000,100000,quadruped")
    args = ap.parse_args()
    if args.child:
        return child(args.child[0], args.child[1], args.repeat, args.solver)
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; solver "
          f"{args.solver}")
    print(f"{'case':10s} {'method':6s} {'V':>7s} {'J':>3s} {'best s':>7s} {'median':>7s} "
          f"{'max':>7s} {'cpu s':>6s} {'peak MB':>8s}  stages (best wall, s)")
    for name in args.cases.split(","):
        for method in ("heat", "idw"):
            out = subprocess.run([sys.executable, __file__, "--child", name, method,
                                  "--repeat", str(args.repeat), "--solver", args.solver],
                                 capture_output=True, text=True, check=True).stdout
            r = json.loads(out.strip().splitlines()[-1])
            t = np.array(r["totals"])
            st = " ".join(f"{k} {r['stages'][k]:.3f}" for k in STAGES if k in r["stages"])
            print(f"{name:10s} {method:6s} {r['vertices']:7d} {r['joints']:3d} {t.min():7.3f} "
                  f"{np.median(t):7.3f} {t.max():7.3f} {min(r['cpu']):6.3f} {r['peak_mb']:8.0f}  {st}")


if __name__ == "__main__":
    main()
