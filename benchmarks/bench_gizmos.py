#!/usr/bin/env python3
"""What the joint spheres cost in the editor, in one run (issue 12, section 1): the actor of
sphere imposters of today against the glyph actor of 144-triangle spheres before it and the
forty ``vtkSphereWidget`` s before that.

1. Static re-renders of the editor's 3D view (the quadruped, side view, window 1280x720 by
   default) in three settings, interleaved over rounds (the machine's speed drifts), median
   of the rounds' medians: the joint spheres as one actor of imposters (the editor now); no
   joint spheres; one ``vtkGlyph3DMapper`` actor of 12 x 8 spheres (144 triangles) at the same
   points and colours; forty vtkSphereWidgets built as the editor built them before (16 x 12
   resolution, surface, in the overlay renderer), the imposters hidden. The joints' cost is each setting minus
   the one without spheres. Wall time and this process's CPU time (all its threads).
2. Python per mouse move: moving all spheres onto a new pose (glyph points in place against
   forty ``SetCenter`` calls) and the hover pick of the mouse ray against every sphere.
3. The look: the view rendered with the glyphs and with the widgets (same pose, camera and
   everything else), the share of pixels that differ and by how much; ``--save DIR`` writes
   both images.
4. ``--drag``: only a real drag (profile_drag's: press on the ``fore_cannon_L`` sphere, 120
   mouse moves through the VTK interactor, release), the wall time per move and this
   process's CPU time per move. It uses only what every version of the editor has, so that
   two commits can be compared: ``PYTHONPATH=OLD_TREE xvfb-run ... bench_gizmos.py --drag``
   then the same with the new tree, in turn.

Run: ``xvfb-run -a -s "-screen 0 1600x1000x24" .venv/bin/python benchmarks/bench_gizmos.py
[--size 1280x720] [--rounds 15] [--save DIR] [--drag]``.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
sys.path.append(str(Path(__file__).resolve().parents[1]))  # after PYTHONPATH: see --drag
sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

import rigedit  # noqa: E402  (imported before profile_drag puts this tree first on the path)
from profile_drag import (_limb_joint, _median_ms, drag, open_editor,  # noqa: E402
                          wall_and_cpu_ms)


def old_widgets(w):
    """Forty vtkSphereWidgets as ``render/gizmos.py`` built them before the glyph actor."""
    import vtk

    from rigedit.render.joint_glyphs import SPHERE_COLOR

    iren = w.plotter.iren.interactor
    widgets = []
    for p in w.gizmos.positions:
        s = vtk.vtkSphereWidget()
        s.SetInteractor(iren)
        s.SetCurrentRenderer(w.overlay)
        s.SetDefaultRenderer(w.overlay)
        s.SetRepresentationToSurface()
        s.SetThetaResolution(16)
        s.SetPhiResolution(12)
        s.ScaleOff()
        s.GetSphereProperty().SetColor(SPHERE_COLOR)
        s.GetSphereProperty().SetSpecular(0.4)
        s.SetRadius(w.gizmos.radius)
        s.SetCenter(*p)
        widgets.append(s)
    return widgets


def old_glyphs(w):
    """The joints as the editor drew them before the imposters: one ``vtkGlyph3DMapper``
    actor of 12 x 8 spheres (144 triangles) at the same points, in the same colours."""
    import vtk

    from rigedit.render.joint_glyphs import SPHERE_COLOR

    source = vtk.vtkSphereSource()
    source.SetRadius(w.gizmos.radius)
    source.SetThetaResolution(12)
    source.SetPhiResolution(8)
    mapper = vtk.vtkGlyph3DMapper()
    mapper.SetInputData(w.gizmos.glyphs.points)
    mapper.SetSourceConnection(source.GetOutputPort())
    mapper.ScalingOff()
    mapper.OrientOff()
    mapper.SetScalarModeToUsePointFieldData()
    mapper.SelectColorArray("rgb")
    mapper.SetColorModeToDirectScalars()
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().SetSpecular(0.4)
    actor.GetProperty().SetSpecularColor(SPHERE_COLOR)
    actor.SetVisibility(False)
    w.overlay.AddActor(actor)
    return actor


def compare_look(w, others, folder=None):
    """Pixels of the view with the imposters against the same view with each older way
    (``others``: name -> set_visible(on))."""
    import imageio.v2 as imageio

    w.plotter.render()
    now = w.plotter.screenshot(return_img=True)[:, :, :3].astype(int)
    shots = {"imposters": now}
    for name, show in others.items():
        w.gizmos.set_visible(False)
        show(True)
        w.plotter.render()
        shots[name] = w.plotter.screenshot(return_img=True)[:, :, :3].astype(int)
        show(False)
        w.gizmos.set_visible(True)
        w.plotter.render()
        diff = np.abs(now - shots[name]).max(axis=2)
        changed = diff > 8
        print(f"\nthe look: view with imposters vs with {name}")
        print(f"  pixels differing by more than 8 levels: {changed.mean():.3%} of the view; "
              f"their mean difference {diff[changed].mean() if changed.any() else 0:.1f} "
              f"levels; mean over all pixels {np.abs(now - shots[name]).mean():.2f}")
    if folder:
        Path(folder).mkdir(parents=True, exist_ok=True)
        for name, shot in shots.items():
            imageio.imwrite(Path(folder) / f"gizmos-{name.replace(' ', '-')}.png",
                            shot.astype(np.uint8))


def drag_frames(app, w, rounds=3, moves=120):
    """Wall ms (median) and CPU ms (mean) per mouse move of ``rounds`` real drags."""
    j = _limb_joint(w.document.skeleton)
    print(f"rigedit from {Path(rigedit.__file__).parent}")
    for k in range(rounds):
        c0 = time.process_time()
        per_move, renders, _ = drag(app, w, j, moves)
        cpu = (time.process_time() - c0) / moves * 1e3
        print(f"  drag {k + 1}: wall {np.median(per_move):.1f} ms per move "
              f"({1e3 / np.median(per_move):.1f} frames/s), CPU {cpu:.1f} ms per move, "
              f"{len(renders) / moves:.2f} renders per move")
        w.document.undo()


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", default="1280x720", help="editor window size")
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--save", help="folder for the two images of the look comparison")
    parser.add_argument("--drag", action="store_true", help="only time a real drag")
    args = parser.parse_args()
    from PyQt5 import QtWidgets
    from threadpoolctl import threadpool_limits

    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication([])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig = rigedit.load_rig("quadruped")
    print(f"rig: {rig.name}, {len(rig.faces):,} triangles, {len(rig.skeleton)} joints; "
          f"load average {os.getloadavg()[0]:.2f} at start")
    with threadpool_limits(1):
        w = open_editor(app, rig, tuple(int(v) for v in args.size.split("x")))
        print(f"3D view {w.plotter.width()}x{w.plotter.height()} px")
        if args.drag:
            drag_frames(app, w)
            w.close()
            return
        render = w.plotter.render_window.Render
        widgets = old_widgets(w)
        glyph_actor = old_glyphs(w)
        iren = w.plotter.iren.interactor

        def set_widgets(on):
            iren.EnableRenderOff()
            for s in widgets:
                s.SetEnabled(on)

        settings = [
            ("joint spheres: one actor of imposters (now)", lambda: None, lambda: None),
            ("no joint spheres", lambda: w.gizmos.set_visible(False),
             lambda: w.gizmos.set_visible(True)),
            ("joint spheres: one glyph actor, 144 triangles each (before)",
             lambda: (w.gizmos.set_visible(False), glyph_actor.SetVisibility(True)),
             lambda: (glyph_actor.SetVisibility(False), w.gizmos.set_visible(True))),
            ("joint spheres: 40 vtkSphereWidgets (before)",
             lambda: (w.gizmos.set_visible(False), set_widgets(True)),
             lambda: (set_widgets(False), w.gizmos.set_visible(True))),
        ]
        times = {label: [] for label, _, _ in settings}
        for _ in range(args.rounds):
            for label, on, off in settings:
                on()
                times[label].append(wall_and_cpu_ms(render))
                off()
        none = "no joint spheres"
        print("\nstatic re-render of the view, ms: median over the rounds of each round's "
              "median (best round); the joints' cost is the difference to no spheres")
        for k, clock in enumerate(("wall", "CPU")):
            v = {label: np.array([t[k] for t in ts]) for label, ts in times.items()}
            med = {label: float(np.median(x)) for label, x in v.items()}
            best = {label: float(np.min(x)) for label, x in v.items()}
            print(f" {clock} time")
            for label in v:
                extra = "" if label == none else \
                    f"  joints {med[label] - med[none]:+6.2f} ({best[label] - best[none]:+.2f})"
                print(f"  {label:58s} {med[label]:6.2f} ({best[label]:6.2f}){extra}")

        # Python of a mouse move
        heads = w.gizmos.positions.copy() + 0.01
        glyph_ms = _median_ms(lambda: w.gizmos.set_positions(heads), n=200)

        def widget_centres():
            for s, p in zip(widgets, heads):
                s.SetCenter(float(p[0]), float(p[1]), float(p[2]))
        widget_ms = _median_ms(widget_centres, n=200)
        x, y = w.gizmos.display_position(len(heads) // 2)
        pick_ms = _median_ms(lambda: w.gizmos.pick(x + 40, y + 40), n=200)
        print("\nper mouse move (Python)")
        print(f"  move all spheres onto a pose: imposter points {glyph_ms:.3f} ms, "
              f"40 SetCenter {widget_ms:.3f} ms")
        print(f"  hover pick (mouse ray against {len(heads)} spheres): {pick_ms:.3f} ms")
        compare_look(w, {"glyphs": glyph_actor.SetVisibility, "widgets": set_widgets},
                     args.save)
        for s in widgets:
            s.SetEnabled(False)
            s.SetInteractor(None)
        w.close()
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    sys.exit(main())
