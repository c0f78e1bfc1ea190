#!/usr/bin/env python3
"""Speed of dragging a joint in the editor.

1. Model side of one drag step on the default character, no rendering: IK (chain of 2)
   from the pose at drag start, forward kinematics, skinning palette, linear blend skinning.
   Also the same plus the copy into the VTK mesh and bones (``scene.update_from_matrices``).
2. Frames per second of a real drag in the window under Xvfb: mouse press on a joint sphere,
   N mouse moves, release, through the VTK interactor (each move = one IK solve, skinning,
   in-place point update and one render, counted with a render-window observer).

3. ``--big``: the same window drag on a big character, the quadruped with each triangle
   split at its centroid twice (540,000 triangles, 270,002 vertices, weights interpolated;
   ``rigedit.binding.subdivide``), twice in turn: as the editor draws it (its decimated proxy
   while the joint moves, the full mesh on release) and with the proxy turned off (the full
   mesh every frame); frames/s of each and what the status bar said.

``--compare-ik OLD_IK.py`` times section 1 with another version's ``rigedit/model/ik.py`` too,
interleaved with this tree's, and prints how far apart their solutions are.

Run: ``xvfb-run -a .venv/bin/python benchmarks/bench_drag.py [RIG] [--size 1280x720]
[--big] [--compare-ik OLD_IK.py]``.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402


def _limb_joint(sk):
    for name in ("fore_cannon_L", "hind_cannon_L", "front_foot_L"):
        if name in sk.index:
            return sk.index[name]
    return len(sk) - 1


def drag_targets(rig, steps):
    """The dragged limb joint, the rest pose and (steps, 3) targets on a loop around it."""
    j = _limb_joint(rig.skeleton)
    start = rig.rest_pose()
    head = rig.joint_matrices(start)[j, :3, 3]
    a = np.linspace(0, 6, steps)
    targets = head + 0.15 * rig.height() * np.stack([np.sin(a), np.cos(a) - 1,
                                                     np.zeros(steps)], axis=1)
    return j, start, targets


def model_step(rig, steps=300, drag_joint=None):
    """Median-ready times (ms) of the model side of a drag step (IK, FK, palette, skinning)
    and of the IK alone, over ``steps`` targets, each from the pose at drag start."""
    if drag_joint is None:
        from rigedit.model.ik import drag_joint

    sk = rig.skeleton
    j, start, targets = drag_targets(rig, steps)
    snap = start.as_array()
    work = start.copy()
    times = []
    for t in targets:
        t0 = time.perf_counter()
        work.set_array(snap)
        drag_joint(sk, work, j, t, chain_length=2, fk=rig.joint_matrices)
        model = rig.joint_matrices(work)
        rig.binding.skin(np.matmul(model, sk.inverse_bind_matrices))
        times.append(time.perf_counter() - t0)
    ik = []
    for t in targets:
        t0 = time.perf_counter()
        work.set_array(snap)
        drag_joint(sk, work, j, t, chain_length=2, fk=rig.joint_matrices)
        ik.append(time.perf_counter() - t0)
    return np.array(times) * 1e3, np.array(ik) * 1e3


def load_ik(path):
    """An ``ik.py`` of another version (``git show REV:rigedit/model/ik.py > old_ik.py``),
    loaded as a module of ``rigedit.model`` so its relative imports resolve."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("rigedit.model._ik_compared", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def compare_model_step(rig, other_ik, rounds=5):
    """Model drag step and IK alone, this tree's ``ik`` and ``other_ik`` interleaved over
    ``rounds``; prints the median of each and the largest distance between the joint
    positions the two solve for the same targets."""
    from rigedit.model.ik import drag_joint

    rows = {"this tree": ([], []), other_ik.__file__: ([], [])}
    for _ in range(rounds):
        for label, fn in (("this tree", drag_joint), (other_ik.__file__, other_ik.drag_joint)):
            total, ik = model_step(rig, drag_joint=fn)
            rows[label][0].append(np.median(total))
            rows[label][1].append(np.median(ik))
    for label, (total, ik) in rows.items():
        print(f"  {label:<40} step median {np.median(total):.3f} ms (rounds "
              f"{min(total):.3f}-{max(total):.3f}), IK alone {np.median(ik):.3f} ms "
              f"({min(ik):.3f}-{max(ik):.3f})")
    from rigedit.model.ik import ik_chain

    j, start, targets = drag_targets(rig, 300)
    sk = rig.skeleton
    rest = rig.joint_matrices(start)[:, :3, 3]
    path = ik_chain(sk, j, 2) + [j]
    reach = np.linalg.norm(np.diff(rest[path], axis=0), axis=1).sum()
    worst, misses = 0.0, {"this tree": 0.0, "other": 0.0}
    for t in targets:
        a, b = start.copy(), start.copy()
        drag_joint(sk, a, j, t, chain_length=2, fk=rig.joint_matrices)
        other_ik.drag_joint(sk, b, j, t, chain_length=2, fk=rig.joint_matrices)
        pa, pb = rig.joint_matrices(a)[:, :3, 3], rig.joint_matrices(b)[:, :3, 3]
        worst = max(worst, float(np.abs(pa - pb).max()))
        if np.linalg.norm(t - rest[path[0]]) < reach:
            misses["this tree"] = max(misses["this tree"], float(np.linalg.norm(pa[j] - t)))
            misses["other"] = max(misses["other"], float(np.linalg.norm(pb[j] - t)))
    print(f"  largest joint position difference between the two: {worst:.2e} "
          f"(character height {rig.height():.3f}); largest distance from the dragged joint to "
          f"a reachable target: this tree {misses['this tree']:.1e}, the other "
          f"{misses['other']:.1e}")


def big_rig(rig, levels=2):
    """``rig`` with every triangle split at its centroid ``levels`` times (3**levels times
    the triangles), weights interpolated, same skeleton and clips."""
    from rigedit import Rig
    from rigedit.binding.subdivide import subdivide_centroid

    b = rig.binding
    v, f, idx, w = subdivide_centroid(rig.vertices, rig.faces, b.indices, b.weights,
                                      len(rig.skeleton), levels=levels)
    return Rig(rig.skeleton, v, f, idx, w, clips=rig.clips, name=f"{rig.name} x{3 ** levels}")


def window_drag(rig, size, moves=120, proxy=True, window=None):
    """Frames/s of a real drag in the editor window, renders per move, the scene update's
    ms, undo steps, and the status bar's proxy label during the drag and after it."""
    from PyQt5 import QtWidgets

    from rigedit.ui import MainWindow

    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication([])
    w = window or MainWindow(rig)
    if not proxy:
        w.proxy_view.min_faces = 10 ** 12
        w.scene.detach_proxy()
        w.proxy_view.attach()
    w.resize(*size)
    w.show()
    ready = time.perf_counter() + 120   # the proxy is built in a worker thread
    while w.proxy_view.building and time.perf_counter() < ready:
        app.processEvents()
        time.sleep(0.01)
    for _ in range(10):
        app.processEvents()
    w.view("side")
    w.plotter.render()
    app.processEvents()
    j = _limb_joint(rig.skeleton)
    renders = [0]
    w.plotter.render_window.AddObserver("EndEvent", lambda *a: renders.__setitem__(0, renders[0] + 1))
    iren = w.plotter.iren.interactor
    x, y = w.gizmos.display_position(j)
    x, y = int(round(x)), int(round(y))
    iren.SetEventInformation(x, y)
    iren.InvokeEvent("LeftButtonPressEvent")
    assert w.gizmos.active == j, "the press missed the sphere"
    renders[0] = 0
    t0 = time.perf_counter()
    for k in range(moves):
        a = 2 * np.pi * k / moves
        iren.SetEventInformation(x + int(60 * np.sin(a)), y + int(40 * (1 - np.cos(a))))
        iren.InvokeEvent("MouseMoveEvent")
        app.processEvents()
    elapsed = time.perf_counter() - t0
    n_renders = renders[0]
    during = w.proxy_view.label.text().strip() if w.proxy_view.label.isVisible() else "-"
    iren.InvokeEvent("LeftButtonReleaseEvent")
    app.processEvents()
    settle = time.perf_counter() + 2.0
    while w.scene.proxy_shown and time.perf_counter() < settle:
        app.processEvents()
    after = w.proxy_view.label.text().strip() if w.proxy_view.label.isVisible() else "-"
    # Scene update alone (points into VTK), for the breakdown.
    model = rig.joint_matrices(w.document.pose)
    t1 = time.perf_counter()
    for _ in range(50):
        w.scene.update_from_matrices(model)
    scene_ms = (time.perf_counter() - t1) / 50 * 1e3
    steps = len(w.document.undo_stack)
    w.close()
    return moves / elapsed, n_renders / moves, scene_ms, steps, (during, after)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("rig", nargs="?")
    parser.add_argument("--size", default="1280x720", help="window size")
    parser.add_argument("--no-window", action="store_true")
    parser.add_argument("--big", action="store_true",
                        help="also drag the quadruped split to 540k triangles")
    parser.add_argument("--rounds", type=int, default=2, help="rounds of the --big drags")
    parser.add_argument("--compare-ik", metavar="OLD_IK.py",
                        help="also time the model step with another version's ik.py, "
                             "interleaved with this tree's")
    args = parser.parse_args()
    import rigedit
    from rigedit.model import skinning_kernels

    skinning_kernels.load()   # as app.py does half a second after start

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig = rigedit.load_rig(args.rig)
    print(f"rig: {rig.name}, {len(rig.vertices):,} vertices, {len(rig.faces):,} faces, "
          f"{len(rig.skeleton)} joints")
    with threadpool_limits(1):
        total, ik = model_step(rig)
        print(f"model drag step (IK chain 2 + FK + skinning): median {np.median(total):.2f} ms, "
              f"p95 {np.percentile(total, 95):.2f} ms  (IK alone {np.median(ik):.2f} ms)")
        if args.compare_ik:
            print("model drag step, interleaved (median of 5 rounds of 300 steps):")
            compare_model_step(rig, load_ik(args.compare_ik))
        if not args.no_window:
            size = tuple(int(v) for v in args.size.split("x"))
            fps, per_move, scene_ms, steps, _ = window_drag(rig, size)
            print(f"scene update (points + bones into VTK): {scene_ms:.2f} ms")
            print(f"window drag at {args.size} under {os.environ.get('DISPLAY', '?')}: "
                  f"{fps:.1f} frames/s, {per_move:.2f} renders per mouse move, "
                  f"{steps} undo step(s)")
        if args.big and not args.no_window:
            t0 = time.perf_counter()
            big = big_rig(rig)
            print(f"\nbig character: {len(big.vertices):,} vertices, {len(big.faces):,} "
                  f"triangles (built in {time.perf_counter() - t0:.1f} s)")
            rows = {True: [], False: []}
            for _ in range(args.rounds):
                for proxy in (True, False):
                    t0 = time.perf_counter()
                    res = window_drag(big, size, moves=40, proxy=proxy)
                    rows[proxy].append((res[0], res[1], res[4], time.perf_counter() - t0))
            for proxy, label in ((True, "as the editor draws it (proxy while moving)"),
                                 (False, "full mesh every frame (proxy off)")):
                fps = [r[0] for r in rows[proxy]]
                print(f"  {label:<45} {max(fps):5.1f} frames/s (rounds "
                      f"{', '.join(f'{f:.1f}' for f in fps)}; "
                      f"{np.mean([r[1] for r in rows[proxy]]):.2f} renders/move; window "
                      f"open to close {min(r[3] for r in rows[proxy]):.1f} s)")
                print(f"      status bar during the drag: {rows[proxy][0][2][0]!r}; "
                      f"after the release: {rows[proxy][0][2][1]!r}")
            print(f"load average: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    sys.exit(main())
