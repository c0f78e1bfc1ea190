"""Sampling a pose of bezier tracks, as a ratio to the same clip with linear/slerp tracks.

A 60-joint chain with a rotation and a translation track per joint (120 tracks), keyed every
1/30 s over 2 s (61 keys per curve), random motion. The cases, each sampling the whole pose
at a random time (``Clip.sample`` into one reused Pose):

- ``plain``: the tracks as keyed, rotations slerp, translations linear (the reference);
- ``bezier``: the same tracks converted to bezier tracks (three curves each, auto_clamped
  handles), sampled through the clip's packed curves (one vectorised call per pose);
- ``bezier, per track``: the bezier tracks sampled one ``Track.sample`` at a time (what
  ``Clip.sample`` would cost without the pack).

Cases are interleaved with the reference (A B A B ...) so load on the machine hits both
alike; it prints the median wall time and the best CPU time (``time.process_time``) per
pose, and the ratios to ``plain``.

Then, on a mocap clip (CMU 131_01.bvh from the shared test data, 994 keys per track, skipped
when missing), what the graph editor does with dense keys, each the median of ``--repeat``
runs beside the reference, the rotation track's own ``sample_many`` at the same 1000 times:
``channels`` of one joint (the conversion to curves, uncached), ``ChannelView.sample`` of one
rotation channel at 1000 times, and one ``CurveDrag.update`` (the clip changed and the pose
sampled again).

Last, FBX export's refinement of one rotation track (``fbx_write_anim.rotation_keys``, keys
until FBX's linear Euler keys are within 2e-4 degrees) on a bezier track of the clip, beside
the same track as slerp.

Run: ``.venv/bin/python benchmarks/bench_curves.py [--poses N] [--repeat N]``.
"""
from __future__ import annotations

import os

os.environ["OMP_NUM_THREADS"] = os.environ["OPENBLAS_NUM_THREADS"] = "1"

import argparse
import time

import numpy as np
from scipy.spatial.transform import Rotation

from rigedit.animation import Clip, Track
from rigedit.animation.curve import Curve
from rigedit.model import Pose, Skeleton

JOINTS = 60
KEYS = 61


def _skeleton():
    names = [f"j{i}" for i in range(JOINTS)]
    t = np.zeros((JOINTS, 3))
    t[1:, 1] = 0.1
    return Skeleton(names, [-1] + list(range(JOINTS - 1)), rest_translation=t)


def clips(seed=0):
    """(plain clip, bezier clip) of the same random motion."""
    sk = _skeleton()
    rng = np.random.default_rng(seed)
    times = np.linspace(0, 2, KEYS)
    plain, bezier = {}, {}
    for name in sk.names:
        q = Rotation.from_rotvec(np.cumsum(rng.normal(0, 0.05, (KEYS, 3)), axis=0)).as_quat()
        v = np.cumsum(rng.normal(0, 0.01, (KEYS, 3)), axis=0)
        plain[(name, "rotation")] = Track("rotation", times, q, "slerp")
        plain[(name, "translation")] = Track("translation", times, v, "linear")
        for channel, tr in ((c, plain[(name, c)]) for c in ("rotation", "translation")):
            curves = tr.with_interpolation("bezier").curves
            bezier[(name, channel)] = Track.from_curves(
                channel, [Curve(c.times, c.values) for c in curves])   # auto_clamped
    return Clip("plain", sk, plain), Clip("bezier", sk, bezier)


def _per_track(clip, pose, t):
    index = clip.skeleton.index
    for (joint, channel), track in clip.tracks.items():
        getattr(pose, channel)[index[joint]] = track.sample(t)


def _time(fn, t):
    w0, c0 = time.perf_counter(), time.process_time()
    fn(t)
    return time.perf_counter() - w0, time.process_time() - c0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--poses", type=int, default=300)
    ap.add_argument("--repeat", type=int, default=9)
    args = ap.parse_args()
    plain, bezier = clips()
    pose = Pose(plain.skeleton)
    # the packed and per-track samplings give the same pose
    for t in np.linspace(0, 2, 7):
        a = bezier.sample(t, out=pose).as_array().copy()
        _per_track(bezier, pose, t)
        assert np.allclose(np.abs(a), np.abs(pose.as_array()), atol=1e-9)
    cases = {"bezier": lambda t: bezier.sample(t, out=pose),
             "bezier, per track": lambda t: _per_track(bezier, pose, t)}
    reference = lambda t: plain.sample(t, out=pose)  # noqa: E731
    rng = np.random.default_rng(1)
    print(f"{JOINTS} joints, {len(plain.tracks)} tracks, {KEYS} keys per curve; "
          f"{args.poses} poses per case; median wall / best CPU per pose")
    for name, fn in cases.items():
        fn(0.5), reference(0.5)   # warm (the clip packs its curves at the first sample)
        ours, ref = [], []
        for t in rng.uniform(0, 2, args.poses):
            ours.append(_time(fn, t))
            ref.append(_time(reference, t))
        ours, ref = np.array(ours), np.array(ref)
        wall, cpu = np.median(ours[:, 0]), ours[:, 1].min()
        rwall, rcpu = np.median(ref[:, 0]), ref[:, 1].min()
        print(f"{name:>18}: {wall * 1e3:7.3f} ms wall, {cpu * 1e3:7.3f} ms CPU | plain "
              f"{rwall * 1e3:7.3f} ms wall, {rcpu * 1e3:7.3f} ms CPU | ratio "
              f"{wall / rwall:5.2f} wall, {cpu / max(rcpu, 1e-9):5.2f} CPU")
    mocap(args.repeat)
    fbx(plain, bezier, max(3, args.repeat // 3))


def _median(fn, repeat):
    out = []
    for _ in range(repeat):
        w = time.perf_counter()
        fn()
        out.append(time.perf_counter() - w)
    return float(np.median(out))


def mocap(repeat):
    """The graph editor's operations on a dense mocap clip (see the module notes)."""
    import warnings
    from pathlib import Path

    import rigedit
    from rigedit.editor import graph_commands as gc
    from rigedit.editor.document import Document

    path = Path("/work/shared/data/bvh-cmu/131_01.bvh")
    if not path.is_file():
        print(f"mocap: skipped ({path} is missing)")
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        doc = Document(rigedit.load_rig(path))
    joint = doc.skeleton.names[1]
    track = doc.clip.tracks[(joint, "rotation")]
    times = np.linspace(0, doc.clip.duration, 1000)
    ref = _median(lambda: track.sample_many(times), repeat)

    def convert():
        gc._CONVERTED.clear()
        return gc.channels(doc, [joint])

    view = next(v for v in convert() if v.id.channel == "rotation" and v.id.axis == 2)
    drag = gc.CurveDrag(doc, "bench")
    moved = view.curve.with_keys_moved([10], 0.0, 5.0)
    cases = {"channels (convert)": convert, "view.sample 1000": lambda: view.sample(times),
             "CurveDrag.update": lambda: drag.update({view.id: moved})}
    print(f"mocap {path.name}: {len(track)} keys per track, {len(doc.clip.tracks)} tracks; "
          f"reference track.sample_many(1000 times) {ref * 1e3:.2f} ms")
    for name, fn in cases.items():
        t = _median(fn, repeat)
        print(f"{name:>18}: {t * 1e3:7.2f} ms median wall, ratio {t / ref:6.1f}")
    drag.cancel()


def fbx(plain, bezier, repeat):
    """FBX's rotation refinement of one bezier track, as a ratio to the slerp track."""
    from rigedit.io.fbx_write_anim import rotation_keys

    key = ("j5", "rotation")
    out = {}
    for name, clip in (("slerp", plain), ("bezier", bezier)):
        out[name] = (_median(lambda c=clip: rotation_keys(c.tracks[key], 2.0), repeat),
                     len(rotation_keys(clip.tracks[key], 2.0)[0]))
    (ts, ns), (tb, nb) = out["slerp"], out["bezier"]
    print(f"FBX rotation_keys: bezier {tb * 1e3:.0f} ms ({nb} keys), slerp {ts * 1e3:.0f} ms "
          f"({ns} keys), ratio {tb / ts:.1f}")


if __name__ == "__main__":
    main()
