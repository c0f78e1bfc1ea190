"""What an autosave costs, on the bundled characters.

Prints the median and worst of N runs of:

- the UI thread's part of a timer autosave (``rigedit.ui.autosave.Autosave.save`` with
  ``background=True``): a shallow copy of the rig with copies of its clips, and the pose
  snapshot;
- the writer thread's part: :func:`rigedit.editor.recovery.write_entry` (a rig folder through
  ``save_rig_folder`` plus ``recovery.json``), what a crash or signal save costs in full;
- reading the entry back (:func:`rigedit.editor.recovery.read_entry`), what Recover costs.

Run: ``.venv/bin/python benchmarks/bench_autosave.py [--runs N]``. The cache folder is a
temporary one.
"""
from __future__ import annotations

import os

os.environ["OMP_NUM_THREADS"] = os.environ["OPENBLAS_NUM_THREADS"] = "1"

import argparse
import copy
import statistics
import tempfile
import time
import warnings


def timed(fn, runs):
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times) * 1000, max(times) * 1000


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    args = parser.parse_args()
    os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(prefix="bench-autosave-")
    import rigedit
    from rigedit.editor import recovery

    print(f"{'rig':<10} {'vertices':>8} {'UI thread ms':>14} {'write ms':>14} {'read ms':>14}"
          "   (median / worst)")
    for name in rigedit.BUNDLED:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rig = rigedit.load_rig(name)
        pose = rig.rest_pose()

        def ui_part():
            snap = copy.copy(rig)
            snap.clips = {n: c.copy() for n, c in rig.clips.items()}
            return snap, pose.as_array()

        ui = timed(ui_part, args.runs)
        write = timed(lambda: recovery.write_entry(rig, pose.as_array(), None, 0.0,
                                                   original_path=rig.path), args.runs)
        entry = recovery.list_entries()[0]
        read = timed(lambda: recovery.read_entry(entry), args.runs)
        recovery.remove_entry(entry.folder)
        print(f"{name:<10} {len(rig.vertices):>8,} " + " ".join(
            f"{m:>7.0f} / {w:<5.0f}" for m, w in (ui, write, read)))


if __name__ == "__main__":
    main()
