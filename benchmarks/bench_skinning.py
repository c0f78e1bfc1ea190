"""Skinning alone, every path, against the memory-copy floor, in one run.

For 10k, 100k and 1M vertices, 40 joints, 4 influences per vertex, random rigid palettes, it
prints the median and best time of one frame (palette -> skinned vertices, float32), twice:
with random weights (all four influences non-zero) and with the bundled quadruped's weights
(its 30k vertices' rows repeated in order: 1.9 non-zero influences of 4 on average, 40
joints), of:

- LBS, the compiled numba kernel on 1 thread and on 2 threads;
- LBS, the numpy path (sparse (V x J) weights times the (J x 12) palette, then apply);
- LBS, a dense reference (a dense float32 (V x J) weight matrix times the palette, einsum);
- DQS, the compiled kernel on 1 and 2 threads, and the numpy reference;
- the floor: the bytes a frame must move (read the float32 rest vertices, the int32 indices
  and float32 weights, write the float32 output: 56 bytes per vertex) at the memory-copy
  bandwidth measured in the same run (``np.copyto`` of 256 MB, read + write).

A second table gives the best CPU time of the calling thread for the one-thread paths: on a
machine shared with busy processes, calls longer than a scheduler time slice are preempted
and their wall time counts the other processes' turns (measured here: 10 ms of CPU for a 1M
LBS frame that took 34-44 ms of wall time at a load of 13 on 2 cores).

Run: ``.venv/bin/python benchmarks/bench_skinning.py [--repeat-scale S]`` (BLAS pinned to one
thread). The kernels are compiled (or loaded from numba's cache) before timing.
"""
from __future__ import annotations

import os

os.environ["OMP_NUM_THREADS"] = os.environ["OPENBLAS_NUM_THREADS"] = "1"

import argparse
import platform
import time

import numpy as np
from scipy.spatial.transform import Rotation
from threadpoolctl import threadpool_limits

from rigedit.model import SkinBinding, skinning_kernels
from rigedit.model.skinning import top_k_influences

J, K = 40, 4
BYTES_PER_VERTEX = 12 + 4 * K + 4 * K + 12  # rest, indices, weights, output
BYTES_WITH_NORMALS = BYTES_PER_VERTEX + 24  # and the rest normals in, the normals out


def timed_ms(fn, repeat):
    """(median wall, best wall, best CPU time of this thread) of one call in ms, after one
    warm-up call. On a machine shared with other busy processes a call longer than a
    scheduler time slice (a few ms) is preempted and its wall time counts theirs; the thread's
    CPU time does not (for the one-thread paths, which run in this thread)."""
    fn()
    wall, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.thread_time()
        fn()
        cpu.append(time.thread_time() - c0)
        wall.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(wall)), 1e3 * float(np.min(wall)), 1e3 * float(np.min(cpu))


def bandwidth_gbs(nbytes=256_000_000, repeat=7):
    """Read + write bandwidth of np.copyto in GB/s from the times of :func:`timed_ms`."""
    a = np.ones(nbytes // 8)
    b = np.empty_like(a)
    return tuple(2 * nbytes / (ms * 1e-3) / 1e9 for ms in timed_ms(lambda: np.copyto(b, a),
                                                                   repeat))


def random_palettes(rng, n):
    pals = np.tile(np.eye(4), (n, J, 1, 1))
    for i in range(n):
        seed = int(rng.integers(1 << 30))
        pals[i, :, :3, :3] = Rotation.random(J, random_state=seed).as_matrix()
        pals[i, :, :3, 3] = rng.normal(size=(J, 3))
    return pals


def quadruped_weights(v):
    """(V, 4) indices and weights: the bundled quadruped's weights repeated in their order
    (neighbouring vertices of a mesh have similar influences, which the kernel's early stop
    at zero weights relies on for predictable branches)."""
    from rigedit import ASSETS_DIR

    with np.load(ASSETS_DIR / "quadruped" / "weights.npz") as data:
        idx, w, names = data["indices"], data["weights"], data["joints"]
    assert len(names) == J and idx.shape[1] == K
    rows = np.arange(v) % len(idx)
    return idx[rows], w[rows] / w[rows].sum(axis=1, keepdims=True)


def main(repeat_scale=1.0):
    kernels = skinning_kernels.load()
    if kernels is None:
        raise SystemExit(f"compiled kernels unavailable: {skinning_kernels.error()}")
    rng = np.random.default_rng(0)
    pals = random_palettes(rng, 8)
    bw = bandwidth_gbs()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cpus, "
          f"numpy {np.__version__}, numba {kernels.numba.__version__}, one BLAS thread")
    print(f"memory-copy bandwidth: median {bw[0]:.1f} GB/s, best {bw[1]:.1f} GB/s, from CPU "
          f"time {bw[2]:.1f} GB/s (np.copyto of 256 MB, read + write); floor = "
          f"{BYTES_PER_VERTEX} bytes/vertex at that rate")
    cols = ["floor", "LBS 1t", "LBS 2t", "LBS numpy", "dense ref", "DQS 1t", "DQS 2t",
            "DQS numpy"]
    print("ms per frame, median / best of the run; ratios of the medians (and of the bests)")
    print("random weights (4 non-zero influences):")
    print(f"{'vertices':>9} | " + " | ".join(f"{c:>13}" for c in cols)
          + f" | {'LBS1/floor':>13} | {'DQS1/LBS1':>13}")
    cpu_cols = ["floor", "LBS 1t", "LBS numpy", "dense ref", "DQS 1t", "DQS numpy", "floor+n",
                "LBS+n 1t", "DQS+n 1t"]
    cpu_rows = []
    cases = [(v, "random") for v in (10_000, 100_000, 1_000_000)]
    cases += [(v, "quadruped") for v in (10_000, 100_000, 1_000_000)]
    for v, kind in cases:
        if kind == "quadruped" and v == 10_000:
            print("weights of the quadruped:")
        rest = rng.normal(size=(v, 3))
        if kind == "random":
            idx, w = top_k_influences(rng.random((v, J)) ** 8, K)
        else:
            idx, w = quadruped_weights(v)
        binding = SkinBinding(rest, idx, w, J)
        dense = binding.dense().astype(np.float32)
        rest_h = np.c_[rest, np.ones(v)].astype(np.float32)
        state = {"i": 0}

        def palette():
            state["i"] += 1
            return pals[state["i"] % len(pals)]

        def dense_frame():
            p = palette()[:, :3, :].reshape(J, 12).astype(np.float32)
            return np.einsum("vij,vj->vi", (dense @ p).reshape(v, 3, 4), rest_h)

        p0 = pals[0]
        ref = binding.skin(p0, backend="numpy").copy()
        assert np.allclose(binding.skin(p0, backend="numba"), ref, atol=1e-4)
        ref_dqs = binding.skin(p0, method="dqs", backend="numpy").copy()
        assert np.allclose(binding.skin(p0, method="dqs", backend="numba"), ref_dqs, atol=1e-4)
        repeat = max(3, int(repeat_scale * (200 if v <= 10_000 else 60 if v <= 100_000 else 15)))
        row = {"floor": tuple(v * BYTES_PER_VERTEX / (b * 1e9) * 1e3 for b in bw),
               "floor+n": tuple(v * BYTES_WITH_NORMALS / (b * 1e9) * 1e3 for b in bw)}
        normals = rng.normal(size=(v, 3))
        binding.bind_normals(normals / np.linalg.norm(normals, axis=1, keepdims=True))
        binding.threads = None
        binding.skin(pals[0], backend="numba")  # the output buffer's pages are mapped
        for threads in (1, 2):
            binding.threads = threads
            row[f"LBS {threads}t"] = timed_ms(lambda: binding.skin(palette(), backend="numba"),
                                             repeat)
            row[f"DQS {threads}t"] = timed_ms(
                lambda: binding.skin(palette(), method="dqs", backend="numba"), repeat)
        binding.threads = 1
        for method in ("lbs", "dqs"):
            row[f"{method.upper()}+n 1t"] = timed_ms(
                lambda: binding.skin_with_normals(palette(), backend="numba", method=method),
                repeat)
        row["LBS numpy"] = timed_ms(lambda: binding.skin(palette(), backend="numpy"), repeat)
        row["dense ref"] = timed_ms(dense_frame, max(3, repeat // 4))
        row["DQS numpy"] = timed_ms(
            lambda: binding.skin(palette(), method="dqs", backend="numpy"), max(3, repeat // 4))
        ratios = [tuple(a / b for a, b in zip(row[x][:2], row[y][:2]))
                  for x, y in (("LBS 1t", "floor"), ("DQS 1t", "LBS 1t"))]
        print(f"{v:>9,} | " + " | ".join(f"{row[c][0]:>6.3f}/{row[c][1]:<6.3f}" for c in cols)
              + " | " + " | ".join(f"{r[0]:>5.2f} ({r[1]:.2f})".rjust(13) for r in ratios),
              flush=True)
        cpu_rows.append((v, kind, row))
    print("\nbest CPU time of the calling thread, ms per frame (one thread only; +n: positions "
          f"and normals in one pass, against a floor of {BYTES_WITH_NORMALS} bytes/vertex):")
    print(f"{'vertices':>9} | {'weights':>9} | " + " | ".join(f"{c:>9}" for c in cpu_cols)
          + f" | {'LBS1/floor':>10} | {'DQS1/floor':>10} | {'DQS1/LBS1':>9} | {'DQS+n/fl+n':>10}")
    for v, kind, row in cpu_rows:
        print(f"{v:>9,} | {kind:>9} | " + " | ".join(f"{row[c][2]:>9.3f}" for c in cpu_cols)
              + f" | {row['LBS 1t'][2] / row['floor'][2]:>10.2f}"
              + f" | {row['DQS 1t'][2] / row['floor'][2]:>10.2f}"
              + f" | {row['DQS 1t'][2] / row['LBS 1t'][2]:>9.2f}"
              + f" | {row['DQS+n 1t'][2] / row['floor+n'][2]:>10.2f}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat-scale", type=float, default=1.0,
                        help="multiply the number of timed frames per size")
    with threadpool_limits(1):
        main(parser.parse_args().repeat_scale)
