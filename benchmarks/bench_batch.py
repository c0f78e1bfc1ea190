"""Batch jobs on Dask (issue 21): throughput with 1 and 2 local workers, auto-rigging the
shared meshes, and the engine's per-task overhead.

Run: ``.venv/bin/python benchmarks/bench_batch.py [--copies N] [--rounds R] [--skip-retarget]
[--skip-autorig] [--skip-noop] [--thumbnails]``

**Retarget throughput**: every BVH clip in ``../shared/data/bvh-*`` (12 clips), copied
``--copies`` times (3 by default, each copy its own file and task), onto three targets (the
bundled ``humanoid``, three.js ``Xbot.glb`` and Khronos ``CesiumMan.glb``): at least 100
tasks, run by ``rigedit.batch.run`` on a local cluster of 1 and then 2 worker processes
(``--no-thumbnails`` unless ``--thumbnails``), ``--rounds`` pairs of runs with the order
alternating (the load of other processes drifts). Tasks per second over the whole run (cluster
start included), the tasks' own seconds summed and their mean, and the workers' CPU seconds
(``getrusage`` of the ended worker processes: CPU per task, and CPU / wall = the cores the
batch got, which tells a slow run from a machine that other work keeps busy); the ratio 2 workers / 1
worker of each pair is measured in the same run, and right after it the reference: the cores
that 1 and 2 busy-loop processes get (what the machine lets two workers have at that moment). The load average before
and after is printed: other processes on the machine share its cores.

**Auto-rig**: ``cow.obj`` (quadruped template) and ``homer.obj`` (humanoid template) from
``../shared/data/common-3d-test-models`` as one batch each on 2 workers: seconds per task.

**Overhead**: 200 ``noop`` tasks (each hashes one 1-byte file and returns its entry) on 1
worker, after 20 to warm the connection: wall time of the tasks divided by their count, minus the same task run in this
process (the reference, measured in the same run), in milliseconds.
"""
from __future__ import annotations

import argparse
import os
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

REPO = Path(__file__).resolve().parent.parent
DATA = REPO.parent / "shared" / "data"
TARGETS = ["humanoid", DATA / "threejs-characters" / "Xbot.glb",
           DATA / "khronos-gltf" / "CesiumMan.glb"]


def load():
    return " ".join(f"{v:.2f}" for v in os.getloadavg())


_SPIN = ("import time\nt0, c0 = time.time(), time.process_time()\n"
         "while time.time() - t0 < {s}: pass\nprint(time.process_time() - c0)")


def cores_available(seconds=3.0):
    """Cores that 1 and then 2 busy-loop processes get right now (CPU seconds / wall):
    the reference for the worker ratio, since other work shares this machine's cores."""
    import subprocess

    got = []
    for n in (1, 2):
        procs = [subprocess.Popen([sys.executable, "-c", _SPIN.format(s=seconds)],
                                  stdout=subprocess.PIPE, text=True) for _ in range(n)]
        got.append(sum(float(p.communicate()[0]) for p in procs) / seconds)
    return got


def copies_of_clips(folder, copies):
    clips = sorted(p for d in DATA.glob("bvh-*") for p in d.rglob("*.bvh"))
    if not clips:
        sys.exit(f"no BVH clips under {DATA}/bvh-*")
    for k in range(copies):
        for clip in clips:
            (folder / f"{clip.stem}_copy{k}.bvh").write_bytes(clip.read_bytes())
    return len(clips)


def children_cpu():
    """CPU seconds of this process's ended children (the local cluster's workers)."""
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def timed_run(job, inputs, out, **options):
    """``rigedit.batch.run``: its summary, wall seconds, the tasks' summed seconds and the
    workers' CPU seconds."""
    from rigedit.batch import run

    cpu, t0 = children_cpu(), time.perf_counter()
    summary = run(job, inputs, out, **options)
    wall = time.perf_counter() - t0
    busy = sum(e["seconds"] or 0 for e in summary.entries)
    return summary, wall, busy, children_cpu() - cpu


def bench_retarget(tmp, copies, thumbnails, rounds=1):
    motions = tmp / "motions"
    motions.mkdir()
    n_clips = copies_of_clips(motions, copies)
    targets = [str(t) for t in TARGETS if str(t) == "humanoid" or Path(t).exists()]
    print(f"retarget: {n_clips} clips x {copies} copies onto {len(targets)} targets "
          f"({', '.join(Path(t).name for t in targets)}), thumbnails "
          f"{'on' if thumbnails else 'off'}")
    for r in range(rounds):
        rates = {}
        for workers in ((1, 2) if r % 2 == 0 else (2, 1)):   # alternate: load drifts
            before = load()
            s, wall, busy, cpu = timed_run("retarget", [motions], tmp / f"retarget{r}_{workers}",
                                           to=targets, workers=workers, thumbnails=thumbnails)
            rates[workers] = s.tasks / wall
            print(f"  round {r + 1}, {workers} worker(s): {s.tasks} tasks, {s.failed} failed, "
                  f"{wall:.1f} s wall ({rates[workers]:.2f} tasks/s), task time summed "
                  f"{busy:.1f} s (mean {busy / s.tasks:.3f} s), workers' CPU {cpu:.1f} s "
                  f"({cpu / s.tasks:.3f} s a task, {cpu / wall:.2f} cores used); load avg "
                  f"before {before}, after {load()}", flush=True)
        one, two = cores_available()
        print(f"  round {r + 1}: throughput 2 workers / 1 worker: {rates[2] / rates[1]:.2f}x; "
              f"reference right after: 1 busy process got {one:.2f} cores, 2 got {two:.2f} "
              f"together ({two / one:.2f}x)", flush=True)


def bench_autorig(tmp):
    meshes = DATA / "common-3d-test-models"
    for mesh, template in (("cow.obj", "quadruped"), ("homer.obj", "humanoid")):
        if not (meshes / mesh).exists():
            print(f"autorig: {mesh} missing, skipped")
            continue
        s, wall, busy, _ = timed_run("autorig", [meshes / mesh], tmp / f"autorig_{template}",
                                  template=template, workers=2)
        e = s.entries[0]
        print(f"autorig {mesh} ({template}): {e['status']}, task {e['seconds']:.1f} s, "
              f"batch wall {wall:.1f} s; {e['quality'].get('orientation')}, "
              f"cost {e['quality'].get('embedding cost')}, unsure {len(e['unsure'])}")


def bench_noop(tmp, count=200):
    from rigedit.batch.engine import Engine
    from rigedit.batch.jobs import run_task
    from rigedit.batch.tasks import check_options, plan

    files = tmp / "noop"
    files.mkdir()
    for i in range(count):
        (files / f"{i:04d}.txt").write_bytes(b"x")
    tasks = plan("noop", sorted(files.iterdir()), tmp, check_options("noop", {}))
    t0 = time.perf_counter()
    for t in tasks:
        run_task(t)
    local = (time.perf_counter() - t0) / count
    with Engine(workers=1, warm=("rigedit.batch.jobs",)) as engine:
        list(engine.map(run_task, tasks[:20]))   # the client's and worker's first calls
        t0 = time.perf_counter()
        n = sum(1 for _ in engine.map(run_task, tasks))
        per = (time.perf_counter() - t0) / n
    print(f"noop: {count} tasks on 1 worker: {1000 * per:.2f} ms per task, in this process "
          f"{1000 * local:.2f} ms: engine overhead {1000 * (per - local):.2f} ms per task")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--copies", type=int, default=3)
    p.add_argument("--thumbnails", action="store_true")
    p.add_argument("--rounds", type=int, default=1,
                   help="pairs of runs (1 and 2 workers, the order alternating)")
    p.add_argument("--skip-retarget", action="store_true")
    p.add_argument("--skip-autorig", action="store_true")
    p.add_argument("--skip-noop", action="store_true")
    args = p.parse_args(argv)
    tmp = Path(tempfile.mkdtemp(prefix="bench_batch_"))
    print(f"cores {os.cpu_count()}, load avg {load()}")
    try:
        if not args.skip_noop:
            bench_noop(tmp)
        if not args.skip_retarget:
            bench_retarget(tmp, args.copies, args.thumbnails, args.rounds)
        if not args.skip_autorig:
            bench_autorig(tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
