"""BVH parse speed: a synthetic file of 10,000 frames on a 31-joint skeleton (CMU's layout:
a 6-channel root and 30 joints of 3 rotation channels, 96 numbers a frame), read by
``rigedit.io.bvh.load_bvh`` into a rig with one clip.

Run: ``.venv/bin/python benchmarks/bench_bvh.py [--frames N] [--repeat R]``; prints the
best and median wall time of R runs, and the best CPU time of this process (on a shared,
busy machine the wall time includes waiting for a core; the CPU time does not).
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("OMP_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rigedit.io.bvh import load_bvh, parse_bvh  # noqa: E402


def synthetic_bvh(frames, joints=31, seed=0):
    """BVH text: a chain-and-branches skeleton of ``joints`` joints, random smooth motion."""
    rng = np.random.default_rng(seed)
    lines = ["HIERARCHY"]
    depth = 0

    def open_joint(kind, name, offset, channels):
        nonlocal depth
        pad = "  " * depth
        lines.extend([f"{pad}{kind} {name}", f"{pad}{{",
                      f"{pad}  OFFSET {offset[0]:.5f} {offset[1]:.5f} {offset[2]:.5f}",
                      f"{pad}  CHANNELS {len(channels)} {' '.join(channels)}"])
        depth += 1

    def close_joint(end=False):
        nonlocal depth
        pad = "  " * depth
        if end:
            lines.extend([f"{pad}End Site", f"{pad}{{", f"{pad}  OFFSET 0 1 0", f"{pad}}}"])
        depth -= 1
        lines.append("  " * depth + "}")

    rot = ["Zrotation", "Xrotation", "Yrotation"]
    open_joint("ROOT", "Hips", (0, 0, 0), ["Xposition", "Yposition", "Zposition"] + rot)
    # five chains of six joints: 30 joints below the root
    for c in range(5):
        for k in range(6):
            open_joint("JOINT", f"c{c}_{k}", rng.normal(size=3) * 5, rot)
        for k in range(6):
            close_joint(end=(k == 0))
    close_joint()
    t = np.linspace(0, 20 * np.pi, frames)[:, None]
    phase = rng.uniform(0, 2 * np.pi, 96)
    data = 40 * np.sin(t + phase) + rng.normal(scale=0.5, size=(frames, 96))
    lines += ["MOTION", f"Frames: {frames}", "Frame Time: 0.0083333"]
    lines += [" ".join(f"{v:.4f}" for v in row) for row in data]
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=10_000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bench.bvh"
        path.write_text(synthetic_bvh(args.frames))
        size = path.stat().st_size
        parse_times, load_times, load_cpu = [], [], []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            parse_bvh(path)
            t1 = time.perf_counter()
            c1 = time.process_time()
            rig = load_bvh(path, scale=0.01)
            c2 = time.process_time()
            t2 = time.perf_counter()
            parse_times.append(t1 - t0)
            load_times.append(t2 - t1)
            load_cpu.append(c2 - c1)
    print(f"BVH {args.frames} frames x {len(rig.skeleton)} joints (96 channels), "
          f"{size / 1e6:.1f} MB, {args.repeat} runs")
    print(f"  parse (text -> arrays):     best {min(parse_times):.3f} s, "
          f"median {np.median(parse_times):.3f} s")
    print(f"  load_bvh (parse + rig):     best {min(load_times):.3f} s, "
          f"median {np.median(load_times):.3f} s; CPU time best {min(load_cpu):.3f} s")
    print(f"  load average: {' '.join(f'{v:.1f}' for v in os.getloadavg())} on "
          f"{os.cpu_count()} cores")


if __name__ == "__main__":
    main()
