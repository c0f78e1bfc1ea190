"""Recording throughput: frames per second of ``record_clip`` at 1280x720.

Run under a display (``xvfb-run -a .venv/bin/python benchmarks/bench_record.py``). Uses the
bundled quadruped's walk (``rigedit.load_rig()``), or a code-built creature when the assets are
not installed. Prints one line per configuration: the whole recorder (skin, render, read back,
encode), and the same without the floor or with 4x anti-aliasing, best of ``--repeat`` runs.
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")


def load():
    import rigedit

    try:
        rig = rigedit.load_rig()
    except (ValueError, OSError):
        from rigedit.ui.fallback import demo_rig

        rig = demo_rig()
    clip = rig.clips.get("walk") or next(iter(rig.clips.values()), None)
    return rig, clip


def run(rig, clip, path, frames, fps, size, repeat, **options):
    from rigedit.render.recorder import record_clip

    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        n = record_clip(rig, clip, path, fps=fps, duration=frames / fps, size=size, **options)
        best = min(best, time.perf_counter() - t0)
    return n, n / best, path.stat().st_size


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=60)
    ap.add_argument("--fps", type=float, default=30)
    ap.add_argument("--size", type=int, nargs=2, default=(1280, 720))
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args(argv)
    rig, clip = load()
    size = tuple(args.size)
    print(f"{rig.name}: {len(rig.vertices):,} vertices, {len(rig.faces):,} triangles, "
          f"{len(rig.skeleton)} joints; clip {clip.name if clip else None}; "
          f"{size[0]}x{size[1]}, {args.frames} frames, best of {args.repeat} (includes the "
          f"plotter's set-up, about 0.3 s)")
    configs = [
        ("MP4 H.264 veryfast (default)", ".mp4", {}),
        ("MP4 H.264 medium preset", ".mp4", {"preset": "medium"}),
        ("MP4, no floor", ".mp4", {"show_floor": False}),
        ("MP4, 4x MSAA", ".mp4", {"multi_samples": 4}),
        ("GIF", ".gif", {}),
    ]
    with tempfile.TemporaryDirectory() as tmp:
        for label, suffix, options in configs:
            path = Path(tmp) / f"bench{suffix}"
            n, fps, nbytes = run(rig, clip, path, args.frames, args.fps, size, args.repeat,
                                 **options)
            print(f"  {label:32s} {fps:6.1f} frames/s   ({n} frames, {nbytes / 1e6:.1f} MB)")


if __name__ == "__main__":
    main()
