"""Retargeting quality and time: the shared BVH files onto the bundled humanoid and CesiumMan,
and the bundled quadruped's clips onto quadrupeds of other proportions and names.

    .venv/bin/python benchmarks/bench_retarget.py [--markdown] [--quadruped-only] [--autorig]

For each pair: the mean angle between each mapped target bone and its source bone in model
space (arms, legs = thigh and shin, spine, head; feet apart: their pitch is transferred
relative to each figure's flat foot), the foot slip per contact (horizontal path of the ankle
or toe joint during each detected source contact, mm: the source's own scaled to the target,
the target before and after the clean-up), the lowest foot point relative to the target's
floor (mm, before and after), and the time of the retarget.

Quadrupeds (``tests/quadruped_variants.py`` builds the targets from the bundled skeleton):
the same measures per chain group (legs: every bone from the shoulder blade or hip down to
the hoof; spine: pelvis to the fore legs' branch; head: neck, head, jaw, ears, antlers; tail),
the slip of each hoof joint during its contacts, and the time of each clip and of all four.
A target with other joint names is retargeted with a JSON-style map and with the map found
from the trees' shape (:mod:`rigedit.rigging.retarget.tree_map`).

``--autorig``: also each template's clips onto characters auto-rigged from it
(``rigedit.autorig(mesh, template, clips=False)``, then :func:`retarget_result` per clip, as
the auto-rigging does): the bundled characters' own meshes and the shared cow and homer.
"""
from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import rigedit
from rigedit.rigging import retarget_result
from rigedit.rigging.retarget.measure import (direction_errors, foot_slip, lowest_foot,
                                     source_foot_points, target_foot_points)

REPO = Path(__file__).resolve().parents[1]
DATA = REPO.parent / "shared" / "data"
SOURCES = {"CMU 131_01": DATA / "bvh-cmu" / "131_01.bvh",
           "Bandai walk": DATA / "bvh-bandai" / "dataset-1_walk_normal_002.bvh",
           "Bandai run": DATA / "bvh-bandai" / "dataset-1_run_normal_001.bvh"}
TARGETS = {"humanoid": "humanoid", "CesiumMan": DATA / "khronos-gltf" / "CesiumMan.glb"}


def _table(head, rows, markdown):
    if markdown:
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for r in rows:
            print("| " + " | ".join(r) + " |")
    else:
        widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(head)]
        for r in [head] + rows:
            print("  ".join(c.rjust(w) for c, w in zip(r, widths)))


def _measures(res, groups):
    """Direction errors of ``groups``, slips (source scaled, before, after), contacts, lowest
    foot point before and after (mm)."""
    err = direction_errors(res)
    src_slip = foot_slip(source_foot_points(res), res.contact) * res.scale
    before = foot_slip(target_foot_points(res, res.raw_mats), res.contact)
    after = foot_slip(target_foot_points(res), res.contact)
    mean = lambda x: f"{1000 * x.mean():.1f}" if len(x) else "-"  # noqa: E731
    return ([f"{err[g]:.2f}" for g in groups] + [mean(x) for x in (src_slip, before, after)]
            + [str(len(after)), f"{1000 * lowest_foot(res, res.raw_mats):.1f}",
               f"{1000 * lowest_foot(res):.1f}"])


def humanoids(markdown):
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
            rows.append([sname, tname] + _measures(res, ("arms", "legs", "spine", "head",
                                                          "feet")) + [f"{dt:.2f}"])
    _table(head, rows, markdown)


def quadrupeds(markdown):
    sys.path.insert(0, str(REPO / "tests"))
    from quadruped_variants import FORE, VARIANTS, fore_variant, renamed, variant

    quad = rigedit.load_rig("quadruped")
    head = ["clip", "target", "legs°", "spine°", "neck/head°", "tail°", "slip src mm",
            "slip before", "slip after", "contacts", "lowest before mm", "lowest after mm",
            "time s"]
    targets = {"itself": (quad, None)}
    targets.update({v: (variant(quad.skeleton, **kw), None) for v, kw in VARIANTS.items()})
    targets.update({v: (fore_variant(quad.skeleton, f), None) for v, f in FORE.items()})
    first = next(iter(VARIANTS))
    other = variant(quad.skeleton, **VARIANTS[first], rename=renamed)
    targets[f"{first}, other names (map)"] = (other,
                                              {n: renamed(n) for n in quad.skeleton.names})
    targets[f"{first}, other names (found by shape)"] = (other, None)
    rows, totals = [], []
    for tname, (target, mapping) in targets.items():
        total = 0.0
        for clip in ("walk", "run", "idle", "head_nod"):
            t0 = time.perf_counter()
            res = retarget_result(quad, clip, target, map=mapping)
            dt = time.perf_counter() - t0
            total += dt
            if clip in ("walk", "run"):
                rows.append([clip, tname] + _measures(res, ("legs", "spine", "head", "tail"))
                            + [f"{dt:.3f}"])
        totals.append(f"{tname}: {total:.2f} s")
    _table(head, rows, markdown)
    print()
    print("all four clips (walk, run, idle, head_nod), wall time per target: "
          + "; ".join(totals))


AUTORIG = [(REPO / "assets" / "quadruped" / "mesh.obj", "quadruped"),
           (DATA / "common-3d-test-models" / "cow.obj", "quadruped"),
           (REPO / "assets" / "humanoid" / "mesh.obj", "humanoid"),
           (DATA / "common-3d-test-models" / "homer.obj", "humanoid")]


def autorigged(markdown):
    head = ["mesh", "template clip", "calibrated as", "legs°", "others° (max)", "slip src mm",
            "slip before", "slip after", "contacts", "lowest before mm", "lowest after mm",
            "time s"]
    rows, notes = [], []
    for mesh, template in AUTORIG:
        name = f"{mesh.parent.name}/{mesh.name}"
        t0 = time.perf_counter()
        try:
            rig = rigedit.autorig(mesh, template=template, clips=False)
        except ValueError as exc:
            notes.append(f"{name}: not auto-rigged: {exc}")
            continue
        notes.append(f"{name}: auto-rigged as {template} in {time.perf_counter() - t0:.1f} s")
        source = rigedit.load_rig(template)
        for clip in source.clips:
            t0 = time.perf_counter()
            res = retarget_result(source, clip, rig)
            dt = time.perf_counter() - t0
            cal = res.target_calibration
            others = [g for g in cal.groups if g not in ("legs", "feet")]
            m = _measures(res, ["legs"] + others)
            rows.append([name, clip, cal.kind, m[0],
                         f"{max(float(x) for x in m[1:1 + len(others)]):.2f}"]
                        + m[1 + len(others):] + [f"{dt:.3f}"])
    _table(head, rows, markdown)
    print()
    for n in notes:
        print(n)


def main():
    markdown = "--markdown" in sys.argv
    warnings.simplefilter("ignore")
    if "--quadruped-only" not in sys.argv:
        humanoids(markdown)
        print()
    quadrupeds(markdown)
    if "--autorig" in sys.argv:
        print()
        autorigged(markdown)


if __name__ == "__main__":
    main()
