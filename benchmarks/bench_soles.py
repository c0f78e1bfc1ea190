"""Feet on the floor, measured on the skin: retargets and auto-rigged template clips.

    .venv/bin/python benchmarks/bench_soles.py [--markdown] [--no-autorig] [--library]

For each case the clip is retargeted with :func:`rigedit.rigging.retarget_result` twice:
"before" with the skin step (:func:`rigedit.rigging.retarget.soles.hold_soles`) replaced by a
no-op (the joint clean-up alone, as rigedit did before it), "after" as it is. Measured on the
skinned feet (each foot's vertices, :func:`rigedit.rigging.retarget.soles.find_soles`: at least half
their weight on the ankle and the joints below it), relative to the floor (the lowest sole
point in the target's calibration pose, its rest):

- lowest: the lowest skinned foot point over all frames (mm; negative is below the floor);
- below: the share of frames in which a sole is more than 1 mm below the floor;
- standing height: the highest a foot's lowest point stands above the floor (or, with a
  minus, sinks into it) in the *standing* frames of its contacts, where the source's foot
  stands within 1% of the hip height of the lowest it stands in that contact (the contact
  tolerance, 6%, also counts the first lift of a foot), the worst frame (mm);
- slip: per contact of a foot (its standing frames, as above), the horizontal path of the
  point bearing the weight (each frame's lowest vertex followed to the next frame), mean and
  worst contact (mm);
- time: the whole retarget, after, wall clock and this process's CPU time (s; the machine
  is shared, so the wall clock waits for other work too).

Cases: the Bandai walk and CMU 131_01 onto the bundled humanoid, CesiumMan and Xbot; the
bundled humanoid's and quadruped's own clips onto themselves; the shared homer.obj and cow.obj
auto-rigged (``rigedit.autorig(..., clips=False)``, then each template clip retargeted, as
the auto-rigging does). ``--library``: instead, every clip of ``bvh-library/`` (Bandai
dataset-2, the iClone rig) onto the three humanoid targets.
"""
from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path
from unittest import mock

import numpy as np

import rigedit
from rigedit.rigging import retarget_result
from rigedit.rigging.retarget.soles import sole_measures

from bench_retarget import _table

REPO = Path(__file__).resolve().parents[1]
DATA = REPO.parent / "shared" / "data"
SOURCES = {"Bandai walk": DATA / "bvh-bandai" / "dataset-1_walk_normal_002.bvh",
           "CMU 131_01": DATA / "bvh-cmu" / "131_01.bvh"}
TARGETS = {"humanoid": "humanoid", "CesiumMan": DATA / "khronos-gltf" / "CesiumMan.glb",
           "Xbot": DATA / "threejs-characters" / "Xbot.glb"}
AUTORIG = {"homer.obj": (DATA / "common-3d-test-models" / "homer.obj", "humanoid"),
           "cow.obj": (DATA / "common-3d-test-models" / "cow.obj", "quadruped")}


def _passthrough(rig, tgt, rot, hips_pos, mats, *args, **kwargs):
    return rot, hips_pos, mats


def measure(res, rig, source):
    """Skin measures of one retarget (see the module docstring), in metres."""
    m = sole_measures(res, rig, source)
    slips = m["slips"]
    return dict(lowest=m["lowest"], below=m["below"], height=m["standing"],
                slip=float(slips.mean()) if len(slips) else float("nan"),
                slip_max=float(slips.max()) if len(slips) else float("nan"),
                contacts=len(slips), floor=m["floor"])


def run(source, clip, target):
    """``(before, after, seconds)`` measures of one case."""
    with mock.patch("rigedit.rigging.retarget.pipeline.hold_soles", _passthrough):
        before = measure(retarget_result(source, clip, target), target, source)
    t0, c0 = time.perf_counter(), time.process_time()
    res = retarget_result(source, clip, target)
    dt = (time.perf_counter() - t0, time.process_time() - c0)
    return before, measure(res, target, source), dt, len(res.times)


def cases(autorig=True, library=False):
    sources = dict(SOURCES)
    if library:
        sources = {f"{p.parent.name}/{p.stem}": p
                   for p in sorted((DATA / "bvh-library").glob("*/*.bvh"))}
    for tname, tpath in TARGETS.items():
        target = rigedit.load_rig(tpath)
        for sname, spath in sources.items():
            source = rigedit.load_rig(spath)
            yield sname, tname, source, next(iter(source.clips)), target
    if library:
        return
    for name in ("humanoid", "quadruped"):
        rig = rigedit.load_rig(name)
        for clip in sorted(rig.clips):
            yield f"{name} {clip}", f"{name} (itself)", rig, clip, rig
    if autorig:
        for mname, (path, template) in AUTORIG.items():
            t0 = time.perf_counter()
            rig = rigedit.autorig(path, template=template, clips=False)
            print(f"{mname}: auto-rigged as {template} in {time.perf_counter() - t0:.1f} s",
                  file=sys.stderr)
            source = rigedit.load_rig(template)
            for clip in sorted(source.clips):
                yield f"{template} {clip}", f"{mname} (auto-rigged)", source, clip, rig


def main():
    markdown = "--markdown" in sys.argv
    warnings.simplefilter("ignore")
    head = ["clip", "target", "frames", "floor y mm", "lowest before mm", "lowest after mm",
            "frames below -1 mm before", "after", "standing height before mm", "after",
            "slip before mm (mean/max)", "slip after mm (mean/max)", "contacts", "time s",
            "CPU s"]
    rows = []
    for sname, tname, source, clip, target in cases("--no-autorig" not in sys.argv,
                                                     "--library" in sys.argv):
        b, a, dt, n = run(source, clip, target)
        mm = lambda x: f"{1000 * x:.1f}"  # noqa: E731
        rows.append([sname, tname, str(n), mm(a["floor"]), mm(b["lowest"]), mm(a["lowest"]),
                     f"{100 * b['below']:.0f}%", f"{100 * a['below']:.0f}%",
                     mm(b["height"]), mm(a["height"]),
                     f"{mm(b['slip'])} / {mm(b['slip_max'])}",
                     f"{mm(a['slip'])} / {mm(a['slip_max'])}", str(a["contacts"]),
                     f"{dt[0]:.2f}", f"{dt[1]:.2f}"])
        print("  ".join(rows[-1]), file=sys.stderr)
    _table(head, rows, markdown)

if __name__ == "__main__":
    main()
