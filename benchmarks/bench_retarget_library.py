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
  relative to each figure's flat foot by design (:mod:`rigedit.rigging.retarget.transfer`);
- ``flat feet°``: every bone again, the feet measured as designed: each foot or toe bone
  against its source bone pitched by the bone's constant offset (the median over the
  frames), i.e. whether the foot moves as its source moves from its flat foot;
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
from bench_retarget import _table  # noqa: E402  (the benchmarks folder is on sys.path)
from rigedit.rigging import retarget_result
from rigedit.model.transforms import unit
from rigedit.rigging.retarget.measure import direction_errors
from rigedit.rigging.retarget.transfer import end_points, pitch_of, pitched

REPO = Path(__file__).resolve().parents[1]
DATA = REPO.parent / "shared" / "data"
XBOT = DATA / "threejs-characters" / "Xbot.glb"
CESIUM = DATA / "khronos-gltf" / "CesiumMan.glb"
FIGURE = DATA / "khronos-gltf" / "RiggedFigure.glb"
TARGETS = {"humanoid": "humanoid", "CesiumMan": CESIUM, "Xbot": XBOT}


def sources():
    """(label, path) of every shared motion file, in library order."""
    out = [(f"Bandai {p.stem.split('_')[1]}", p)
           for p in sorted((DATA / "bvh-bandai").glob("*.bvh"))]
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


def _means(res, mats):
    """Mean angle over every measured bone, over those outside the feet (each bone's mean
    over the frames, :func:`direction_errors` per group weighted by its bones), and the
    worst single frame outside the feet."""
    err = direction_errors(res, mats)
    tgt = res.target_calibration
    count = {g: 0 for g in tgt.groups}
    for j, *_ in res.pairs:
        if tgt.group(j) is not None:
            count[tgt.group(j)] += 1

    def mean(groups):
        n = sum(count[g] for g in groups)
        return sum(count[g] * err[g] for g in groups if count[g]) / n if n else float("nan")
    body = [g for g in tgt.groups if g != "feet"]
    n_body = sum(count[g] for g in body)
    n_feet = count.get("feet", 0)
    rel = (n_body * mean(body) + n_feet * feet_relative(res, mats)) / (n_body + n_feet) \
        if n_feet else mean(body)
    return mean(tgt.groups), mean(body), err["worst"], rel


def feet_relative(res, mats):
    """Mean angle of the foot and toe bones to their source bones once the source bone is
    pitched by the bone's constant offset (the median over the frames of target pitch minus
    source pitch): what the feet's design keeps, each foot moving as its source moves from
    its own flat foot."""
    tgt = res.target_calibration
    out = []
    for j, t_spec, s, s_spec in res.pairs:
        if tgt.group(j) != "feet":
            continue
        vt = end_points(mats, t_spec) - mats[:, j, :3, 3]
        vs = end_points(res.source_mats, s_spec) - res.source_mats[:, s, :3, 3]
        vs = pitched(vs, float(np.median(pitch_of(vs) - pitch_of(vt))))  # up by the offset
        cos = np.sum(unit(vt) * unit(vs), axis=1)
        out.append(np.degrees(np.arccos(np.clip(cos, -1, 1))).mean())
    return float(np.mean(out)) if out else float("nan")


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
                    rows.append([label, clip, tname, "-", "error: " + str(exc)[:60]] + [""] * 7)
                    continue
                dt = time.perf_counter() - t0
                b_all, b_body, _, b_rel = _means(res, res.raw_mats)
                a_all, a_body, worst, a_rel = _means(res, res.mats)
                numbers.append((label, tname, a_all, a_body, dt, len(res.mapping), a_rel))
                rows.append([label, clip, tname, str(len(res.mapping)), f"{b_all:.2f}",
                             f"{a_all:.2f}", f"{b_body:.2f}", f"{a_body:.2f}", f"{b_rel:.2f}",
                             f"{a_rel:.2f}", f"{worst:.1f}",
                             f"{dt:.2f}"])
    return rows, numbers


def main(argv):
    markdown = "--markdown" in argv
    rows, numbers = run()
    head = ["source", "clip", "target", "mapped", "bones° before", "bones° after",
            "no feet° before", "no feet° after", "flat feet° before", "flat feet° after",
            "worst° after", "s"]
    _table(head, rows, markdown)
    print()
    summary = []
    for tname in TARGETS:
        mine = [n for n in numbers if n[1] == tname]
        if not mine:
            continue
        summary.append([tname, str(len(mine)), f"{max(n[2] for n in mine):.2f}",
                        f"{np.mean([n[2] for n in mine]):.2f}",
                        f"{max(n[3] for n in mine):.2f}", f"{max(n[6] for n in mine):.2f}",
                        f"{max(n[4] for n in mine):.2f}"])
    _table(["target", "clips", "max bones° after", "mean bones° after", "max no feet° after",
            "max flat feet° after", "max s"], summary, markdown)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
