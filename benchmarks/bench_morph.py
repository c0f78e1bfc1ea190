"""Morph targets in the skinning frame: what they cost, as a ratio to the frame without them.

On the bundled quadruped's mesh and weights (30k vertices, 40 joints; and the same repeated
10 times, 300k vertices), with a random rigid palette per frame, one frame is
``set_morph_weights`` (when the weights change) then ``SkinBinding.skin`` (LBS, the compiled
kernel on one thread, float32), for:

- ``none``: a binding without morph targets (the reference);
- ``control``: a second binding without morph targets (what alternating two bindings costs
  by itself: the noise floor of the ratios);
- ``zero, set once``: two targets (a sparse one moving 2% of the vertices, a dense one
  moving all), every weight 0, set before the frames (the kernel's path alone);
- ``zero``: the same, with ``set_morph_weights`` of zeros called every frame (as the editor's
  playback samples the clip's weights every frame);
- ``sparse held``: the sparse target at 0.5, the weight unchanged between frames;
- ``sparse animated``: the sparse target's weight changes every frame;
- ``dense animated``: the dense target's weight changes every frame;
- ``dense by hand``: what a dense apply would cost instead (``rest + w * deltas`` over every
  vertex, then the kernel on that buffer), the alternative to storing each target's moved
  rows only.

Each case's frames are interleaved with the reference's (A B A B ...) so that load on the
machine hits both alike; it prints the median wall time and the best CPU time of the thread
per frame, of the case and of ``none`` beside it, and their ratios (on a loaded machine the
best CPU time is the steadier figure: a wall time counts other processes' turns).

Run: ``.venv/bin/python benchmarks/bench_morph.py [--frames N]``.
"""
from __future__ import annotations

import os

os.environ["OMP_NUM_THREADS"] = os.environ["OPENBLAS_NUM_THREADS"] = "1"

import argparse
import time

import numpy as np
from scipy.spatial.transform import Rotation

import rigedit
from rigedit.model import SkinBinding, skinning_kernels
from rigedit.model.morph import MorphTargets


def _palettes(n_joints, count, seed=0):
    rng = np.random.default_rng(seed)
    out = np.tile(np.eye(4), (count, n_joints, 1, 1))
    out[:, :, :3, :3] = Rotation.random(count * n_joints, random_state=seed).as_matrix() \
        .reshape(count, n_joints, 3, 3)
    out[:, :, :3, 3] = rng.normal(scale=0.1, size=(count, n_joints, 3))
    return out


def _targets(vertices, seed=0):
    """A sparse target (the 2% of vertices highest up) and a dense one (all vertices)."""
    rng = np.random.default_rng(seed)
    v = len(vertices)
    deltas = np.zeros((2, v, 3), np.float32)
    top = np.argsort(vertices[:, 1])[-max(1, v // 50):]
    deltas[0, top] = rng.normal(scale=0.01, size=(len(top), 3))
    deltas[1] = rng.normal(scale=0.01, size=(v, 3))
    return MorphTargets(("sparse", "dense"), deltas)


def _pair(ref, case, frames):
    """Interleaved timings: (median wall ms, best CPU ms) of ``ref`` and of ``case``."""
    ref(0), case(0)
    walls, cpus = ([], []), ([], [])
    for i in range(frames):
        for k, fn in enumerate((ref, case)):
            t0, c0 = time.perf_counter(), time.thread_time()
            fn(i)
            cpus[k].append(time.thread_time() - c0)
            walls[k].append(time.perf_counter() - t0)
    return [(1e3 * np.median(w), 1e3 * np.min(c)) for w, c in zip(walls, cpus)]


def run(vertices, indices, weights, n_joints, frames):
    palettes = _palettes(n_joints, 16)
    mt = _targets(vertices)
    plain = SkinBinding(vertices, indices, weights, n_joints)
    other = SkinBinding(vertices, indices, weights, n_joints)
    morphed = SkinBinding(vertices, indices, weights, n_joints, morphs=mt)
    plain.threads = other.threads = morphed.threads = 1
    rest32 = plain._rest32
    dense32 = mt.deltas[1]
    buf = np.empty_like(rest32)
    kernels = skinning_kernels.load()

    def none(i):
        plain.skin(palettes[i % 16], backend="numba")

    def with_weights(w_of_frame):
        def frame(i):
            morphed.set_morph_weights(w_of_frame(i))
            morphed.skin(palettes[i % 16], backend="numba")
        return frame

    def dense_by_hand(i):
        np.multiply(dense32, np.float32(0.25 + 0.5 * ((i % 7) / 7)), out=buf)
        np.add(buf, rest32, out=buf)
        plain._palette16.reshape(-1, 4, 4)[:] = palettes[i % 16].transpose(0, 2, 1)
        kernels.run("lbs", len(buf), 1, buf, plain._indices32, plain._weights32,
                    plain._palette16, plain._out)

    zero = np.zeros(2)
    cases = {
        "control": lambda i: other.skin(palettes[i % 16], backend="numba"),
        "zero, set once": lambda i: morphed.skin(palettes[i % 16], backend="numba"),
        "zero": with_weights(lambda i: zero),
        "sparse held": with_weights(lambda i: [0.5, 0.0]),
        "sparse animated": with_weights(lambda i: [0.25 + 0.5 * ((i % 7) / 7), 0.0]),
        "dense animated": with_weights(lambda i: [0.0, 0.25 + 0.5 * ((i % 7) / 7)]),
        "dense by hand": dense_by_hand,
    }
    print(f"\n{len(vertices):,} vertices, {n_joints} joints, {indices.shape[1]} influences; "
          f"sparse target moves {len(mt.moved_rows(0)):,} vertices; {frames} frames each")
    print(f"{'case':<18}{'median ms':>10}{'best CPU':>10}{'ref median':>11}{'ref CPU':>9}"
          f"{'ratio':>7}{'CPU ratio':>10}")
    for name, fn in cases.items():
        (rm, rc), (cm, cc) = _pair(none, fn, frames)
        print(f"{name:<18}{cm:>10.3f}{cc:>10.3f}{rm:>11.3f}{rc:>9.3f}{cm / rm:>7.2f}"
              f"{cc / rc:>10.2f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=400)
    args = ap.parse_args()
    if skinning_kernels.load() is None:
        raise SystemExit(f"the compiled kernels do not load: {skinning_kernels.error()}")
    rig = rigedit.load_rig("quadruped")
    b = rig.binding
    run(rig.vertices, b.indices, b.weights, len(rig.skeleton), args.frames)
    big = np.concatenate([rig.vertices + [0, 0, 3 * i] for i in range(10)])
    run(big, np.tile(b.indices, (10, 1)), np.tile(b.weights, (10, 1)), len(rig.skeleton),
        max(40, args.frames // 10))


if __name__ == "__main__":
    main()
