"""Retargeting every shared clip onto the three kinds of target the issue judges: the bundled
humanoid, a glTF humanoid (CesiumMan) and a Mixamo character (Xbot).

    .venv/bin/python benchmarks/bench_retarget_library.py [--markdown] [--summary]

Clips: the Bandai walk and run, the five Bandai dataset-2 clips, CMU 131_01, the four CMU
clips on the iClone / Character Creator rig, Xbot's seven clips, CesiumMan's and
RiggedFigure's. For each clip and target (default settings of
:func:`rigedit.rigging.retarget_result`, the automatic map):

- ``mapped``: joints in the map (source -> target);
- ``bones°``: mean angle between each mapped target bone and its source bone, model space,
  after the facing turn, over all frames, averaged over the bones (every measured bone:
  arms, legs, spine, head, fingers and feet), before and after the foot clean-up;
- ``no feet°``: the same without the foot and toe bones, whose pitch is transferred
  relative to each figure's flat foot by design (:mod:`rigedit.rigging.transfer`);
- ``worst°``: the largest single-frame angle of a bone outside the feet, after the clean-up;
- ``s``: the time of the retarget (``perf_counter``; loading the files left out).

A failure to retarget is a row with the error's first words.
"""
from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

import rigedit
from rigedit.rigging import retarget_result
from rigedit.rigging.transfer import end_points

REPO = Path(__file__).resolve().parents[1]
DATA = REPO.parent / "shared" / "data"
XBOT = DATA / "threejs-characters" / "Xbot.glb"
CESIUM = DATA / "khronos-gltf" / "CesiumMan.glb"
FIGURE = DATA / "khronos-gltf" / "RiggedFigure.glb"
TARGETS = {"humanoid": "humanoid", "CesiumMan": CESIUM, "Xbot": XBOT}


def sources():
    """(label, path) of every shared motion file, in library order."""
    out = [(f"Bandai {p.stem.split('_')[1]}", p) for p in sorted((DATA / "bvh-bandai").glob("*.bvh"))]
    out += [(f"Bandai-2 {p.stem.split('_')[1]}", p)
            for p in sorted((DATA / "bvh-library" / "bandai-2").glob("*.bvh"))]
    out += [("CMU 131_01", DATA / "bvh-cmu" / "131_01.bvh")]
    out += [(f"iClone {p.stem}", p)
            for p in sorted((DATA / "bvh-library" / "cmu-iclone").glob("*.bvh"))]
    out += [("Xbot", XBOT), ("CesiumMan", CESIUM), ("RiggedFigure", FIGURE)]
    return out


def _load(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rigedit.load_rig(path)


def bone_errors(res, mats):
    """Mean angle (degrees) per measured bone pair over the frames, and whether it is a foot
    bone: ``[(angle, is_foot, worst)]``."""
    tgt = res.target_calibration
    out = []
    for j, t_spec, s, s_spec in res.pairs:
        g = tgt.group(j)
        if g is None:
            continue
        vt = end_points(mats, t_spec) - mats[:, j, :3, 3]
        vs = end_points(res.source_mats, s_spec) - res.source_mats[:, s, :3, 3]
        cos = np.sum(vt * vs, axis=1) / (np.linalg.norm(vt, axis=1) * np.linalg.norm(vs, axis=1))
        ang = np.degrees(np.arccos(np.clip(cos, -1, 1)))
        out.append((float(ang.mean()), g == "feet", float(ang.max())))
    return out


def _means(errs):
    every = np.mean([e for e, _, _ in errs])
    body = [e for e, foot, _ in errs if not foot]
    worst = max((w for _, foot, w in errs if not foot), default=float("nan"))
    return float(every), float(np.mean(body)) if body else float("nan"), worst


def run():
    """Rows ``[source, clip, target, mapped, bones before, bones after, no feet before,
    no feet after, worst, seconds]`` (strings), and the numbers for the summary."""
    targets = {name: _load(path) for name, path in TARGETS.items()}
    rows, numbers = [], []
    for label, path in sources():
        src = _load(path)
        for clip in src.clips:
            for tname, target in targets.items():
                t0 = time.perf_counter()
                try:
                    res = retarget_result(src, clip, target)
                except ValueError as exc:
                    rows.append([label, clip, tname, "-", "error: " + str(exc)[:60]] + [""] * 5)
                    continue
                dt = time.perf_counter() - t0
                b_all, b_body, _ = _means(bone_errors(res, res.raw_mats))
                a_all, a_body, worst = _means(bone_errors(res, res.mats))
                numbers.append((label, tname, a_all, a_body, dt, len(res.mapping)))
                rows.append([label, clip, tname, str(len(res.mapping)), f"{b_all:.2f}",
                             f"{a_all:.2f}", f"{b_body:.2f}", f"{a_body:.2f}", f"{worst:.1f}",
                             f"{dt:.2f}"])
    return rows, numbers


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


def main(argv):
    markdown = "--markdown" in argv
    rows, numbers = run()
    head = ["source", "clip", "target", "mapped", "bones° before", "bones° after",
            "no feet° before", "no feet° after", "worst° after", "s"]
    _table(head, rows, markdown)
    print()
    summary = []
    for tname in TARGETS:
        mine = [n for n in numbers if n[1] == tname]
        if not mine:
            continue
        summary.append([tname, str(len(mine)), f"{max(n[2] for n in mine):.2f}",
                        f"{np.mean([n[2] for n in mine]):.2f}",
                        f"{max(n[3] for n in mine):.2f}", f"{max(n[4] for n in mine):.2f}"])
    _table(["target", "clips", "max bones° after", "mean bones° after", "max no feet° after",
            "max s"], summary, markdown)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
