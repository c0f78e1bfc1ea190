"""Per-frame cost of forward kinematics plus linear blend skinning, on one core.

For 10k, 100k and 1M vertices with 40 joints and 4 influences per vertex it prints the median
time of one frame (pose -> local matrices -> FK -> palette -> skinned vertices) with rigedit's
sparse binding, the same frame with a dense reference (a (V, J) weight matrix times every
joint's matrix), and the machine's memory-copy bandwidth, all in one run.

Run: ``.venv/bin/python benchmarks/bench_pipeline.py`` (BLAS pinned to one thread).
"""
from __future__ import annotations

import os

os.environ["OMP_NUM_THREADS"] = os.environ["OPENBLAS_NUM_THREADS"] = "1"

import platform
import time

import numpy as np
from scipy.spatial.transform import Rotation
from threadpoolctl import threadpool_limits

from rigedit.model import (Pose, Skeleton, SkinBinding, local_to_model, skinning_kernels,
                           skinning_matrices)
from rigedit.model.skinning import top_k_influences
from rigedit.binding.weights import compute_weights

J, K = 40, 4


def median_ms(fn, repeat):
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times))


def make_skeleton(rng):
    parents = np.array([-1] + [int(rng.integers(max(0, j - 4), j)) for j in range(1, J)])
    return Skeleton([f"j{i}" for i in range(J)], parents, rng.normal(size=(J, 3)) * 0.2)


def bandwidth_gbs(nbytes=400_000_000):
    a = np.ones(nbytes // 8)
    b = np.empty_like(a)
    ms = median_ms(lambda: np.copyto(b, a), 5)
    return 2 * nbytes / (ms * 1e-3) / 1e9  # read + write


def main():
    # The editor's path: the compiled kernels once loaded (see bench_skinning.py for each path).
    kernels = skinning_kernels.load()
    print(f"skinning: {'compiled kernels' if kernels else 'numpy'}")
    rng = np.random.default_rng(0)
    sk = make_skeleton(rng)
    poses = [Pose(sk, rotation=Rotation.random(J, random_state=i).as_quat()) for i in range(8)]
    print(f"machine: {platform.processor() or platform.machine()}, numpy {np.__version__}, "
          f"one BLAS thread")
    print(f"memory copy bandwidth: {bandwidth_gbs():.1f} GB/s (read + write, np.copyto of "
          f"400 MB)")
    print(f"{'vertices':>9} | {'FK+skin (ms)':>12} | {'dense ref (ms)':>14} | "
          f"{'speed-up':>8} | {'bytes/frame at bandwidth (ms)':>29}")
    bw = bandwidth_gbs(100_000_000)
    for v in (10_000, 100_000, 1_000_000):
        rest = rng.normal(size=(v, 3))
        idx, w = top_k_influences(rng.random((v, J)) ** 8, K)
        binding = SkinBinding(rest, idx, w, J)
        dense = binding.dense()
        rest_h = np.c_[rest, np.ones(v)]
        state = {"i": 0}

        def frame():
            pose = poses[state["i"] % len(poses)]
            state["i"] += 1
            palette = skinning_matrices(sk, local_to_model(sk, pose))
            return binding.skin(palette)

        def dense_frame():
            pose = poses[state["i"] % len(poses)]
            state["i"] += 1
            palette = skinning_matrices(sk, local_to_model(sk, pose))
            blended = (dense @ palette[:, :3, :].reshape(J, 12)).reshape(v, 3, 4)
            return np.einsum("vij,vj->vi", blended, rest_h)

        ref = dense_frame()
        state["i"] -= 1
        got = frame()
        assert np.allclose(got, ref, atol=1e-3), "sparse and dense skinning disagree"
        repeat = 200 if v <= 10_000 else 60 if v <= 100_000 else 12
        ms = median_ms(frame, repeat)
        ms_dense = median_ms(dense_frame, max(5, repeat // 4))
        # Bytes a frame must at least touch: weights (K floats + K ints), rest and out vertices.
        nbytes = v * (K * 4 + K * 4 + 12 + 12)
        print(f"{v:>9,} | {ms:>12.2f} | {ms_dense:>14.2f} | {ms_dense / ms:>7.1f}x | "
              f"{nbytes / bw / 1e6:>29.2f}")


def bench_weights(rng):
    """Automatic weights (inverse distance) for 100k vertices and a 40-joint skeleton."""
    parents = np.r_[-1, [rng.integers(0, j) for j in range(1, J)]]
    sk = Skeleton([f"j{i}" for i in range(J)], parents, rng.normal(size=(J, 3)))
    verts = rng.normal(size=(100_000, 3))
    ms = median_ms(lambda: compute_weights(verts, sk, "idw", K), 5)
    print(f"idw weights, 100,000 vertices, {J} joints ({len(sk.bone_segments()[2])} bone "
          f"segments): {ms / 1e3:.2f} s (median of 5)")


if __name__ == "__main__":
    with threadpool_limits(1):
        main()
        bench_weights(np.random.default_rng(1))
