"""Animation compression core (issue 20): speed against a reference measured in the same run,
and the ratio and error on the shared data, step by step.

Run: ``.venv/bin/python benchmarks/bench_compress_core.py [--speed] [--ratio] [--cubic]``
(speed and ratio by default; ``--cubic``: the gain of Catmull-Rom keys, on and off in one
run). Figures go into docs/compression.md with the date and the machine's load.

**Speed** (wall time, best of a few repeats, the machine's other work included):

- compressing a 1,000-frame, 31-joint clip (every joint's rotation and the root's
  translation keyed at 120 Hz, smooth random swings: ``tests/compression``'s ``mocap_clip``)
  at 1e-4 m: ``compress_clips`` seconds, against the reference of sampling the same clip at
  its 1,000 frames with ``Clip.sample`` (the uncompressed playback of every frame);
- decoding one pose of a 60-joint clip (300 frames, compressed at 1e-4 m) with
  ``CompressedClip.sample(t, out=pose)`` (compiled kernels) against ``Clip.sample(t,
  out=pose)`` of the uncompressed clip, mean over 20,000 calls at spread times;
- a batch: ``CompressedClip.sample_many(1,000 times)`` per pose, against the same reference.

**Ratio**: each clip of the shared data compressed at the bound given, the report's ratio,
max and 99th percentile error (every frame, virtual vertices at 3 cm), and the bytes each step
leaves: raw (40 bytes per joint per frame), constant tracks dropped (animated tracks as float32
at every frame), quantised (every frame a key, at the bits chosen), keys reduced (the file).
"""
from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests" / "compression"))
sys.path.insert(0, str(HERE.parent / "tests"))

from compression_characters import chain, mocap_clip  # noqa: E402
from testpaths import DATA  # noqa: E402

import rigedit  # noqa: E402
from rigedit.compression import compress_clips  # noqa: E402
from rigedit.compression.quantise import PER_KEY  # noqa: E402
from rigedit.model.pose import Pose  # noqa: E402


def best(fn, repeats=3):
    out = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return min(out)


def per_call(fn, args, repeats=3):
    return min(best(lambda: [fn(a) for a in args], 1) for _ in range(repeats)) / len(args)


def speed():
    sk = chain(31, 0.05)
    clip = mocap_clip(sk, frames=1000, rate=120.0)
    compress_clips(sk, {"take": clip}, max_error=1e-4)         # warm (numba, caches)
    pose = Pose(sk)
    frames = np.arange(1000) / 120.0
    ref = best(lambda: [clip.sample(t, out=pose) for t in frames])
    took = best(lambda: compress_clips(sk, {"take": clip}, max_error=1e-4))
    print(f"compress 1000 frames x 31 joints: {took:.3f} s; reference (Clip.sample of every "
          f"frame) {ref:.3f} s; ratio {took / ref:.2f}")
    sk = chain(60, 0.03)
    clip = mocap_clip(sk, frames=300, rate=120.0)
    packed = compress_clips(sk, {"take": clip}, max_error=1e-4).clips["take"]
    assert packed.use_kernels()
    pose = Pose(sk)
    times = np.random.default_rng(0).uniform(0, clip.duration, 20000)
    one = per_call(lambda t: packed.sample(t, out=pose), times)
    ref = per_call(lambda t: clip.sample(t, out=pose), times[:2000])
    print(f"decode one 60-joint pose: {one * 1e6:.1f} us; reference Clip.sample "
          f"{ref * 1e6:.1f} us; ratio {one / ref:.3f}")
    batch = np.linspace(0, clip.duration, 1000)
    many = best(lambda: packed.sample_many(batch), 5) / 1000
    print(f"decode a batch of 1000 poses: {many * 1e6:.2f} us each; ratio to the reference "
          f"{many / ref:.4f}")


def step_bytes(packed, row):
    """(constant dropped, quantised every frame, keys reduced) bytes of one clip, each with
    the clip's headers (what the file needs besides the values and key times)."""
    layout = packed.layout
    frames = len(layout.times)
    kinds = row.bytes_by_kind
    header = row.compressed_bytes - sum(kinds[k] for k in ("rotation", "translation", "scale"))
    header -= kinds["times"] - (0 if layout.uniform else 4 * frames)
    dropped = quantised = header + sum(4 * len(tr.value) for tr in layout.constant)
    for tr in layout.animated:
        width = 4 if tr.channel == "rotation" else 3
        dropped += frames * width * 4
        stride = int(np.sum(tr.code.bits)) + (2 if tr.mode == PER_KEY else 0)
        quantised += frames * stride / 8
    return dropped, quantised, row.compressed_bytes


CASES = [("bvh-cmu/131_01.bvh", (5e-4, 1e-4)),
         ("bvh-bandai/dataset-1_run_normal_001.bvh", (5e-4, 1e-4)),
         ("bvh-bandai/dataset-1_walk_normal_002.bvh", (5e-4, 1e-4)),
         ("threejs-characters/Xbot.glb", (1e-4,)),
         ("threejs-characters/RobotExpressive.glb", (1e-4,))]


def ratio():
    warnings.simplefilter("ignore")
    for rel, bounds in CASES:
        path = DATA / rel
        if not path.exists():
            print(f"{rel}: missing, skipped")
            continue
        rig = rigedit.load_rig(path)
        for bound in bounds:
            t = time.perf_counter()
            result = compress_clips(rig.skeleton, rig.clips, max_error=bound)
            took = time.perf_counter() - t
            rep = result.report
            raw = rep.raw_bytes
            steps = np.sum([step_bytes(c, row) for c, row in
                            zip(result.clips.values(), rep.clips)], axis=0)
            print(f"{rel} at {bound * 100:g} cm: ratio {rep.ratio:.1f}:1, max "
                  f"{rep.max_error * 100:.4f} cm, p99 {rep.p99_error * 100:.4f} cm, "
                  f"{took:.2f} s; raw {raw} -> constant dropped {steps[0]:.0f} "
                  f"({raw / steps[0]:.1f}:1) -> quantised {steps[1]:.0f} "
                  f"({raw / steps[1]:.1f}:1) -> keys reduced {rep.compressed_bytes} "
                  f"({rep.ratio:.1f}:1); bytes {rep.bytes_by_kind}")


def cubic_gain():
    """Catmull-Rom keys on and off (``encode.CUBIC_KEYS``) in the same run: the shared clips,
    and the bundled characters' clips as they are (LINEAR / SLERP keys) and with their keys
    made ``catmull_rom`` (what an animator's spline clips are)."""
    from rigedit.animation import Clip
    from rigedit.compression import encode

    warnings.simplefilter("ignore")
    assets = HERE.parent / "assets"
    cases = [(DATA / rel, bounds, False) for rel, bounds in CASES]
    cases += [(assets / name, (5e-4, 1e-4), spline) for name in ("quadruped", "humanoid")
              for spline in (False, True)]
    for path, bounds, spline in cases:
        if not path.exists():
            print(f"{path}: missing, skipped")
            continue
        rig = rigedit.load_rig(path)
        clips = rig.clips
        if spline:
            clips = {n: Clip(n, rig.skeleton, {k: tr.with_interpolation("catmull_rom")
                                               for k, tr in c.tracks.items()},
                             c.duration, c.loop) for n, c in clips.items()}
        for bound in bounds:
            row = []
            for on in (False, True):
                encode.CUBIC_KEYS = on
                t = time.perf_counter()
                result = compress_clips(rig.skeleton, clips, max_error=bound)
                took = time.perf_counter() - t
                cubic = sum(tr.cubic for c in result.clips.values()
                            for tr in c.layout.animated)
                tracks = sum(len(c.layout.animated) for c in result.clips.values())
                row.append(f"{result.report.ratio:.2f}:1 ({cubic}/{tracks} cubic, "
                           f"{took:.2f} s)")
            encode.CUBIC_KEYS = True
            print(f"{path.name}{' (catmull_rom keys)' if spline else ''} at {bound * 100:g} "
                  f"cm: linear only {row[0]}; with Catmull-Rom keys {row[1]}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--speed", action="store_true")
    parser.add_argument("--ratio", action="store_true")
    parser.add_argument("--cubic", action="store_true",
                        help="the gain of Catmull-Rom keys (on and off in one run)")
    args = parser.parse_args()
    both = not (args.speed or args.ratio or args.cubic)
    if args.speed or both:
        speed()
    if args.ratio or both:
        ratio()
    if args.cubic:
        cubic_gain()


if __name__ == "__main__":
    main()
