#!/usr/bin/env python3
"""How different the editor window looks before and after a change (issue 12, section 4).

Runs the editor of two versions of rigedit, each in its own process: ``--before COMMIT``
(extracted with ``git archive`` into a temporary folder) and the working tree (or
``--after COMMIT``). Each opens the bundled quadruped in a 1500x900 window, shows the walk
at ``--time`` seconds (a posed character, where skinned normals differ from recomputed ones),
saves a screenshot of the window, then hides the mesh and saves a second one: the pixels
that change are the mesh's. It prints, over the mesh's pixels (those of either version), over
the floor's (the 3D view's pixels that are neither mesh nor changed by hiding it, below the
horizon) and over the whole window: the share of pixels that differ, the mean absolute
difference (levels of 255, largest channel) and the share differing by more than 10 and 40
levels; and writes ``before.png``, ``after.png`` and ``diff.png`` (differences x8) to
``--out``.

Run: ``xvfb-run -a -s "-screen 0 1600x1000x24" .venv/bin/python
benchmarks/compare_screenshots.py --before COMMIT [--after COMMIT] [--out DIR]``.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def child(out, clip_time):
    """In the version whose folder is the working directory: the two screenshots."""
    import warnings

    sys.path.insert(0, os.getcwd())
    from PyQt5 import QtWidgets

    import rigedit
    from rigedit.ui import MainWindow

    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication([])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig = rigedit.load_rig()
    w = MainWindow(rig)
    w.resize(1500, 900)   # above either version's minimum size, so both windows match
    w.show()
    for _ in range(20):
        app.processEvents()
    w.document.set_current_clip("walk")
    w.timeline.set_time(clip_time)
    for _ in range(10):
        app.processEvents()
    w.screenshot(f"{out}-window.png")
    w.scene.mesh_actor.SetVisibility(False)
    w.screenshot(f"{out}-nomesh.png")
    top_left = w.plotter.mapTo(w, w.plotter.rect().topLeft())
    Path(f"{out}-view.txt").write_text(
        f"{top_left.x()} {top_left.y()} {w.plotter.width()} {w.plotter.height()}")
    w.close()


def shoot(tree, out, clip_time):
    res = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--child", out,
                          "--time", str(clip_time)], cwd=tree, capture_output=True,
                         text=True, timeout=300)
    if res.returncode != 0:
        raise RuntimeError(f"{tree}: {res.stdout}\n{res.stderr}")


def extract(commit, folder):
    archive = subprocess.run(["git", "archive", commit], cwd=ROOT, capture_output=True,
                             check=True).stdout
    subprocess.run(["tar", "-x", "-C", folder], input=archive, check=True)
    return folder


def stats(diff, mask):
    d = diff[mask]
    if d.size == 0:
        return "no pixels"
    return (f"{mask.sum():>8,} px: {100 * (d > 0).mean():5.1f}% differ, mean "
            f"{d.mean():5.2f} levels, >10: {100 * (d > 10).mean():5.2f}%, >40: "
            f"{100 * (d > 40).mean():5.2f}%")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", help="commit of the version before")
    ap.add_argument("--after", help="commit of the version after (default: working tree)")
    ap.add_argument("--time", type=float, default=0.3, help="walk time shown, seconds")
    ap.add_argument("--out", default="out/compare", help="folder for the pictures")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        return child(args.child, args.time)
    import imageio.v2 as imageio
    import numpy as np

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    shots = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, commit in (("before", args.before), ("after", args.after)):
            tree = extract(commit, tempfile.mkdtemp(dir=tmp)) if commit else str(ROOT)
            if commit:   # the shared test data beside the tree, as beside the repository
                os.symlink(ROOT.parent / "shared", Path(tree).parent / "shared") \
                    if not (Path(tree).parent / "shared").exists() else None
            base = str(Path(tmp) / name)
            shoot(tree, base, args.time)
            window = imageio.imread(f"{base}-window.png")[..., :3].astype(int)
            nomesh = imageio.imread(f"{base}-nomesh.png")[..., :3].astype(int)
            view = [int(v) for v in Path(f"{base}-view.txt").read_text().split()]
            shots[name] = (window, np.abs(window - nomesh).max(axis=2) > 0, view)
            imageio.imwrite(out / f"{name}.png", window.astype(np.uint8))
    (a, mesh_a, view), (b, mesh_b, _) = shots["before"], shots["after"]
    if a.shape != b.shape:
        raise SystemExit(f"window sizes differ: {a.shape} and {b.shape}")
    diff = np.abs(a - b).max(axis=2)
    imageio.imwrite(out / "diff.png", np.clip(diff * 8, 0, 255).astype(np.uint8))
    mesh = mesh_a | mesh_b
    x, y, w, h = view
    in_view = np.zeros_like(mesh)
    in_view[y:y + h, x:x + w] = True
    floor = in_view & ~mesh
    floor[: y + int(0.45 * h)] = False   # below the horizon of the default view
    print(f"before {args.before or 'working tree'}, after {args.after or 'working tree'}; "
          f"walk at {args.time} s; 1500x900 window, 3D view {w}x{h}")
    print(f"  mesh pixels   {stats(diff, mesh)}")
    print(f"  floor pixels  {stats(diff, floor)}")
    print(f"  whole window  {stats(diff, np.ones_like(mesh))}")
    print(f"pictures in {out}/")


if __name__ == "__main__":
    sys.exit(main())
