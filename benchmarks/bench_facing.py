"""Facing: does the target run the way the source runs, its hips facing as the source's do
relative to the path? Every shared clip onto the bundled humanoid, CesiumMan and Xbot.

    .venv/bin/python benchmarks/bench_facing.py [--markdown] [--frame0]

For each clip and target (:func:`rigedit.rigging.retarget_result`, the automatic map):

- ``turn°``: the facing turn applied to the source (a multiple of 90);
- ``source°``: the median over the travelling frames of the source hips' heading relative
  to their path (:func:`rigedit.rigging.retarget.facing.relative_heading`: the pelvis' forward
  against the direction the hips travel over 0.5 s; frames slower than 0.3 leg lengths a
  second have no path, and a clip with none shows ``-``);
- ``offset° mean / max``: the target's relative heading minus the source's
  (:func:`rigedit.rigging.retarget.facing.heading_offsets`), mean and largest absolute value over the
  travelling frames: the issue's target is within 10 degrees.

``--frame0`` judges the facing as before this work, for comparison: the source's forward
from heel to toe in its calibration pose (frame 0 when the rest does not stand), with no
clip-wide judgement.
"""
from __future__ import annotations

import importlib
import sys
import warnings

import numpy as np
from scipy.spatial.transform import Rotation

import rigedit
from bench_retarget import _table  # noqa: E402  (the benchmarks folder is on sys.path)
from bench_retarget_library import TARGETS, sources

# the module, not the function rigedit.rigging exports under the same name
retarget_module = importlib.import_module("rigedit.rigging.retarget.pipeline")
from rigedit.rigging.retarget.facing import heading_degrees, heading_offsets, relative_heading


def _frame0_rule():
    """Make :mod:`rigedit.rigging.retarget.pipeline` judge facing on the calibration pose's feet."""
    def facing(src, tgt, smats):
        a = heading_degrees(tgt.forward) - heading_degrees(src.forward)
        deg = float(np.round(a / 90.0) * 90.0) % 360.0
        return deg, Rotation.from_euler("y", deg, degrees=True).as_matrix()

    retarget_module._facing = facing
    retarget_module.face_by_hips = lambda calib: False


def _row(label, clip, tname, res):
    src = relative_heading(res.source_calibration, res.source_mats, res.times)
    off = np.abs(heading_offsets(res))
    moving = np.isfinite(off)
    return [label, clip, tname, f"{res.facing_degrees:g}",
            f"{np.nanmedian(src):.1f}" if np.isfinite(src).any() else "-",
            f"{off[moving].mean():.2f}" if moving.any() else "-",
            f"{off[moving].max():.2f}" if moving.any() else "-"]


def main(argv):
    markdown = "--markdown" in argv
    if "--frame0" in argv:
        _frame0_rule()
    head = ["source", "clip", "target", "turn°", "source°", "offset° mean", "offset° max"]
    rows = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        targets = {name: rigedit.load_rig(path) for name, path in TARGETS.items()}
        for label, path in sources():
            if path.suffix.lower() != ".bvh":
                continue
            rig = rigedit.load_rig(path)
            for clip in rig.clips:
                for tname, target in targets.items():
                    try:
                        res = retarget_module.retarget_result(rig, clip, target)
                    except ValueError as exc:
                        rows.append([label, clip, tname, "error: " + str(exc)[:60]] + [""] * 3)
                        continue
                    rows.append(_row(label, clip, tname, res))
    _table(head, rows, markdown)


if __name__ == "__main__":
    main(sys.argv[1:])
