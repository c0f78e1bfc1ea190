"""The weights cache: first and second load of the bundled characters without weights.npz.

Run: ``.venv/bin/python benchmarks/bench_weights_cache.py [--repeat N]``.

Each bundled character's folder is copied into a temporary folder without its ``weights.npz``
and loaded with ``rigedit.load_rig`` (heat weights, the default for a mesh) with the cache
pointed at an empty temporary folder (``RIGEDIT_CACHE_DIR``): the first load computes the
weights and stores them, each later load reads them. The reference, in the same run, is the
load of the original folder with its ``weights.npz``. Printed: wall seconds of each (the
best of ``--repeat`` for the cached and the reference loads), the first/second ratio, and the
second load against the reference.
"""
from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
import warnings
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import rigedit  # noqa: E402


def _timed_load(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        rig = rigedit.load_rig(path)
        return time.perf_counter() - t0, rig


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=3)
    args = p.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        os.environ["RIGEDIT_CACHE_DIR"] = str(tmp / "cache")
        print(f"{'character':<10} {'vertices':>8} {'first s':>8} {'second s':>9} "
              f"{'with npz s':>10} {'first/second':>12} {'second/npz':>10}")
        for name in rigedit.BUNDLED:
            src = Path(rigedit.ASSETS_DIR) / name
            folder = tmp / name
            shutil.copytree(src, folder, ignore=shutil.ignore_patterns("weights.npz"))
            rigedit.load_rig(src)   # warm the imports (and numba's kernels) out of the timings
            first, rig = _timed_load(folder)
            second = min(_timed_load(folder)[0] for _ in range(args.repeat))
            ref = min(_timed_load(src)[0] for _ in range(args.repeat))
            print(f"{name:<10} {len(rig.vertices):>8} {first:>8.2f} {second:>9.3f} "
                  f"{ref:>10.3f} {first / second:>12.0f} {second / ref:>10.2f}")


if __name__ == "__main__":
    main()
