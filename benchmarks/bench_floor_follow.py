"""What the recorder's grown floor costs: frames per second of a recording whose floor covers
the clip's travel, against the same recording with the floor kept at its first size.

Run: ``.venv/bin/python benchmarks/bench_floor_follow.py [--frames N] [--size WxH]``.

The bundled quadruped carried forward by its root (a translation track on ``root``) over
``N`` frames at 30 frames/s, recorded to MP4 by ``record_clip`` at the given size with the
camera following, three ways in one run: the floor at its first size (40 cells of 0.5 m, the
reference: :meth:`Floor.reach` replaced by a no-op), the floor grown to a 20 m walk, and grown
to a 2 km walk (capped at ``MAX_CELLS`` cells a side). The three are interleaved over
``--rounds`` rounds and each one's best kept; printed: grid lines, wall frames/s and this
process's CPU milliseconds per frame (the render's, without ffmpeg's), each with its ratio to
the reference.
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np  # noqa: E402

import rigedit  # noqa: E402
from rigedit.animation import Clip, Track  # noqa: E402
from rigedit.render import floor as floor_module  # noqa: E402
from rigedit.render import recorder  # noqa: E402


def _walk(rig, metres, seconds):
    sk = rig.skeleton
    j = sk.index["root"]
    times = np.linspace(0.0, seconds, 9)
    values = sk.rest_translation[j] + np.outer(times / seconds, [0.0, 0.0, metres])
    return Clip("far", sk, {("root", "translation"): Track("translation", times, values)},
                duration=seconds, loop=False)


def _record(rig, clip, size, frames, path):
    """(wall frames/s, CPU ms per frame of this process, grid lines) of one recording."""
    scenes = []

    class Kept(recorder.RigScene):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            scenes.append(self)

    plain, recorder.RigScene = recorder.RigScene, Kept
    try:
        t0, c0 = time.perf_counter(), time.process_time()
        n = recorder.record_clip(rig, clip, path, fps=30, duration=frames / 30.0, size=size)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    finally:
        recorder.RigScene = plain
    return n / wall, 1e3 * cpu / n, scenes[0].floor.grid.n_lines


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--frames", type=int, default=90)
    p.add_argument("--size", default="1280x720")
    p.add_argument("--rounds", type=int, default=3)
    args = p.parse_args(argv)
    size = tuple(int(v) for v in args.size.split("x"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig = rigedit.load_rig("quadruped")
    seconds = args.frames / 30.0
    real_reach = floor_module.Floor.reach
    cases = (("first size (reference)", 20.0, False), ("grown to 20 m", 20.0, True),
             ("grown to 2 km (capped)", 2000.0, True))
    best = {}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.rounds):   # interleaved, so a busy moment hits every case
            for name, metres, grow in cases:
                floor_module.Floor.reach = real_reach if grow else (lambda self, pts: False)
                try:
                    rate, cpu, lines = _record(rig, _walk(rig, metres, seconds), size,
                                               args.frames, Path(tmp) / "v.mp4")
                finally:
                    floor_module.Floor.reach = real_reach
                old = best.get(name, (0.0, np.inf, lines))
                best[name] = (max(old[0], rate), min(old[1], cpu), lines)
    ref_rate, ref_cpu, _ = best[cases[0][0]]
    print(f"quadruped, {args.frames} frames at {size[0]}x{size[1]}, MP4, camera following, "
          f"best of {args.rounds}")
    for name, _, _ in cases:
        rate, cpu, lines = best[name]
        print(f"  {name:<24} {lines:>5} lines  {rate:6.1f} frames/s ({rate / ref_rate:4.2f}x)"
              f"  {cpu:6.1f} CPU ms/frame ({cpu / ref_cpu:4.2f}x)")

if __name__ == "__main__":
    main()
