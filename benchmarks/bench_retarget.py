"""Retargeting quality and time: the shared BVH files onto the bundled humanoid and CesiumMan.

    .venv/bin/python benchmarks/bench_retarget.py [--markdown]

For each pair: the mean angle between each mapped target bone and its source bone in model
space (arms, legs = thigh and shin, spine, head; feet apart: their pitch is transferred
relative to each figure's flat foot), the foot slip per contact (horizontal path of the ankle
or toe joint during each detected source contact, mm: the source's own scaled to the target,
the target before and after the clean-up), the lowest foot point relative to the target's
floor (mm, before and after), and the time of the retarget.
"""
from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import rigedit
from rigedit.rigging import retarget_result
from rigedit.rigging.measure import (direction_errors, foot_slip, lowest_foot,
                                     source_foot_points, target_foot_points)

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
SOURCES = {"CMU 131_01": DATA / "bvh-cmu" / "131_01.bvh",
           "Bandai walk": DATA / "bvh-bandai" / "dataset-1_walk_normal_002.bvh",
           "Bandai run": DATA / "bvh-bandai" / "dataset-1_run_normal_001.bvh"}
TARGETS = {"humanoid": "humanoid", "CesiumMan": DATA / "khronos-gltf" / "CesiumMan.glb"}


def main():
    markdown = "--markdown" in sys.argv
    warnings.simplefilter("ignore")
    head = ["source", "target", "arms°", "legs°", "spine°", "head°", "feet°",
            "slip src mm", "slip before", "slip after", "contacts", "lowest before mm",
            "lowest after mm", "time s"]
    rows = []
    for tname, tpath in TARGETS.items():
        target = rigedit.load_rig(tpath)
        for sname, spath in SOURCES.items():
            source = rigedit.load_rig(spath)
            t0 = time.perf_counter()
            res = retarget_result(source, "take", target)
            dt = time.perf_counter() - t0
            err = direction_errors(res)
            src_slip = foot_slip(source_foot_points(res), res.contact) * res.scale
            before = foot_slip(target_foot_points(res, res.raw_mats), res.contact)
            after = foot_slip(target_foot_points(res), res.contact)
            rows.append([sname, tname] + [f"{err[g]:.2f}" for g in
                                          ("arms", "legs", "spine", "head", "feet")]
                        + [f"{1000 * x.mean():.1f}" for x in (src_slip, before, after)]
                        + [str(len(after)),
                           f"{1000 * lowest_foot(res, res.raw_mats):.1f}",
                           f"{1000 * lowest_foot(res):.1f}", f"{dt:.2f}"])
    if markdown:
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for r in rows:
            print("| " + " | ".join(r) + " |")
    else:
        widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(head)]
        for r in [head] + rows:
            print("  ".join(c.rjust(w) for c, w in zip(r, widths)))


if __name__ == "__main__":
    main()
