#!/usr/bin/env python3
"""Where a drag frame's time goes, in one run (issue 12, section 1).

1. A bare plotter: a QtInteractor (multi_samples 0) in a plain QMainWindow whose render area
   has the same pixel size as the editor's, drawing only the skinned mesh (positions and
   normals skinned in one pass, written in place), with the editor's camera. Median ms of a
   frame (skin + copy + render) and of its render alone.
2. A real joint drag in the editor window (press on a joint sphere, mouse moves, release,
   through the VTK interactor, as ``bench_drag.py``): median ms per mouse move (one frame),
   the ratio to the bare frame, and, in a second drag under cProfile, the time per frame in
   the window's drag handler, IK, FK, skinning and the scene update.
3. The same editor pose re-rendered with each layer hidden in turn (joint spheres, axis
   arrows, bones, the whole overlay renderer, the floor grid, the floor) and with everything
   hidden; vtkPolyDataNormals and the point copy timed alone; the triangles each layer adds.
4. ``--startup``: ``app.py`` (default quadruped, default size) from process start to the end
   of the first render of the window, 3 runs, each in a fresh Python process (the parent
   times the whole process, Python start-up included; the child quits at the first frame).

Run: ``xvfb-run -a -s "-screen 0 1600x1000x24" .venv/bin/python benchmarks/profile_drag.py
[--size 1280x720] [--startup]``.
"""
from __future__ import annotations

T_START = __import__("time").perf_counter()

import argparse  # noqa: E402
import cProfile  # noqa: E402
import os  # noqa: E402
import pstats  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

os.environ.setdefault("OMP_NUM_THREADS", "1")
ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_drag import _limb_joint, drag_targets  # noqa: E402


#: CPU seconds of this process (llvmpipe's drawing threads included) per frame of the last
#: drag, bare_qt_frames or playback call: less sensitive than wall time to other processes
#: on the machine (the X server's copy of the window is in its own process, not counted)
LAST_CPU = []


def wall_and_cpu_ms(fn, n=15, warm=2):
    """Median wall and CPU milliseconds of ``fn()``; the CPU time is this process's, all
    threads (llvmpipe draws on several), so other jobs on the machine inflate it far less
    than the wall time."""
    for _ in range(warm):
        fn()
    wall, cpu = [], []
    for _ in range(n):
        w0, c0 = time.perf_counter(), time.process_time()
        fn()
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - w0)
    return float(np.median(wall) * 1e3), float(np.median(cpu) * 1e3)


def _median_ms(fn, n=30, warm=3):
    """Median wall milliseconds of ``fn()``."""
    return wall_and_cpu_ms(fn, n, warm)[0]


def _pump(app, n=10):
    for _ in range(n):
        app.processEvents()


# ---------------------------------------------------------------------------- editor
def open_editor(app, rig, size):
    from rigedit.ui import MainWindow

    w = MainWindow(rig)
    w.resize(*size)
    w.show()
    _pump(app)
    w.view("side")
    w.plotter.render()
    app.processEvents()
    return w


def drag(app, w, j, moves, profile=None):
    """Press on joint ``j``'s sphere, ``moves`` mouse moves on a loop, release.
    Returns per-move wall times (ms) and per-render times (ms, render window Start->End)."""
    rw = w.plotter.render_window
    stamps = {"t0": 0.0, "r": []}
    obs = [rw.AddObserver("StartEvent", lambda *a: stamps.__setitem__("t0", time.perf_counter())),
           rw.AddObserver("EndEvent", lambda *a: stamps["r"].append(
               time.perf_counter() - stamps["t0"]))]
    iren = w.plotter.iren.interactor
    x, y = (int(round(v)) for v in w.gizmos.display_position(j))
    iren.SetEventInformation(x, y)
    iren.InvokeEvent("LeftButtonPressEvent")
    assert w.gizmos.active == j, "the press missed the sphere"
    app.processEvents()
    stamps["r"].clear()
    per_move, invoke = [], []
    LAST_CPU.clear()
    if profile is not None:
        profile.enable()
    for k in range(moves):
        a = 2 * np.pi * k / moves
        iren.SetEventInformation(x + int(60 * np.sin(a)), y + int(40 * (1 - np.cos(a))))
        t0, c0 = time.perf_counter(), time.process_time()
        iren.InvokeEvent("MouseMoveEvent")
        t1 = time.perf_counter()
        app.processEvents()
        per_move.append(time.perf_counter() - t0)
        invoke.append(t1 - t0)
        LAST_CPU.append(time.process_time() - c0)
    if profile is not None:
        profile.disable()
    renders = list(stamps["r"])
    iren.InvokeEvent("LeftButtonReleaseEvent")
    app.processEvents()
    for o in obs:
        rw.RemoveObserver(o)
    return np.array(per_move) * 1e3, np.array(renders) * 1e3, np.array(invoke) * 1e3


def profile_rows(profile, moves):
    """ms per frame (cumulative, per mouse move) of the drag's Python functions."""
    st = pstats.Stats(profile)
    wanted = {"_drag_move": "window drag handler (all Python of a move)",
              "drag_joint": "  IK (drag_joint, chain 2)",
              "joint_matrices": "  FK (joint_matrices, all calls)",
              "update_from_matrices": "  scene update (skin + copy into VTK + bones)",
              "skin": "    skinning (LBS)",
              "set_positions": "  move the joint spheres (glyph points)",
              "show_joint": "  joint panel refresh"}
    rows = {}
    for (filename, _line, name), (_cc, _nc, _tt, ct, _callers) in st.stats.items():
        if name == "move" and filename.endswith("drag.py"):  # DragController.move
            name = "_drag_move"
        if name in wanted and "rigedit" in filename:
            rows[name] = rows.get(name, 0.0) + ct
    return [(wanted[k], rows[k] / moves * 1e3) for k in wanted if k in rows]


def layer_costs(app, w, rounds=5, n=15):
    """Static re-render of the same pose with layers hidden one at a time. The settings are
    interleaved over ``rounds`` rounds (the machine's speed drifts); the median of the rounds'
    medians is kept."""
    render = w.plotter.render_window.Render
    scene, giz, axes, overlay = w.scene, w.gizmos, w.axes, w.overlay
    grid = w.plotter.actors.get("rig-grid")

    def both(off):
        overlay.SetDraw(not off)
        scene.set_floor_visible(not off)

    settings = [
        ("everything shown (as in the drag)", lambda: None, lambda: None),
        ("joint spheres hidden",
         lambda: giz.set_visible(False), lambda: giz.set_visible(True)),
        ("axis arrows hidden", lambda: axes.set_visible(False), lambda: axes.set_visible(True)),
        ("bones hidden", lambda: scene.set_skeleton_visible(False),
         lambda: scene.set_skeleton_visible(True)),
        ("overlay renderer not drawn (bones + spheres + arrows)",
         overlay.DrawOff, overlay.DrawOn),
        ("floor grid lines hidden", lambda: grid.SetVisibility(False),
         lambda: grid.SetVisibility(True)),
        ("floor hidden (plane + grid)", lambda: scene.set_floor_visible(False),
         lambda: scene.set_floor_visible(True)),
        ("mesh alone (overlay off, floor off)", lambda: both(True), lambda: both(False)),
    ]
    times = {label: [] for label, _, _ in settings}
    for _ in range(rounds):
        for label, off, on in settings:
            off()
            times[label].append(_median_ms(render, n=n))
            on()
    return [(label, float(np.median(times[label])),
             (min(times[label]), max(times[label]))) for label, _, _ in settings]


def layer_triangles(w):
    import pyvista as pv
    import vtk

    if hasattr(w.gizmos, "glyphs"):  # one actor of imposters: a square (2 triangles) each
        sphere_cells = 2
    else:
        pd = vtk.vtkPolyData()
        w.gizmos.widgets[0].GetPolyData(pd)
        sphere_cells = pv.wrap(pd).triangulate().n_cells
    arrows = sum(pv.wrap(a.GetMapper().GetInput()).triangulate().n_cells for a in w.axes.actors)
    floor = w.plotter.actors["rig-floor"].GetMapper().GetInput()
    grid = w.plotter.actors.get("rig-grid")
    bones = w.scene.bones
    return {"mesh triangles": len(w.document.rig.faces),
            "joint spheres": f"{len(w.gizmos.positions)} x {sphere_cells} = "
                             f"{len(w.gizmos.positions) * sphere_cells:,} triangles",
            "axis arrows": f"{arrows:,} triangles",
            "bones": f"{bones.n_lines} lines",
            "floor plane": f"{pv.wrap(floor).triangulate().n_cells:,} triangles",
            "floor grid": f"{pv.wrap(grid.GetMapper().GetInput()).n_cells:,} lines"}


def pipeline_costs(w):
    """FK, skinning with normals, the copy into VTK and vtkPolyDataNormals (what the skinned
    normals replace, run on a copy of the posed mesh), timed alone on the current pose."""
    scene = w.scene
    rig = w.document.rig
    model = rig.joint_matrices(w.document.pose)
    from rigedit.model.kinematics import skinning_matrices

    palette = skinning_matrices(rig.skeleton, model)
    points = rig.binding.skin(palette)
    out = [("FK (joint_matrices)", _median_ms(lambda: rig.joint_matrices(w.document.pose))),
           ("skinning (binding.skin, LBS)", _median_ms(lambda: rig.binding.skin(palette))),
           ("skinning with normals (binding.skin_with_normals, LBS)",
            _median_ms(lambda: rig.binding.skin_with_normals(palette)))]

    def copy():
        scene.mesh.points[:] = points
        scene.mesh.GetPoints().Modified()
        scene.mesh.Modified()
    out.append(("copy points into the VTK mesh", _median_ms(copy)))
    out.append(("scene.update_from_matrices (skin + copy + bones)",
                _median_ms(lambda: scene.update_from_matrices(model))))
    import pyvista as pv

    from rigedit.render.scene import normals_filter

    normals = normals_filter(pv.PolyData(np.array(scene.mesh.points), scene.mesh.GetPolys()))

    def normals_update():
        normals.Modified()
        normals.Update()
    out.append((f"vtkPolyDataNormals ({len(rig.faces):,} triangles; not used)",
                _median_ms(normals_update)))

    def changed_render():
        scene.mesh.Modified()
        w.plotter.render_window.Render()
    out.append(("render after the points changed (upload + draw)",
                _median_ms(changed_render)))
    return out


# ---------------------------------------------------------------------------- bare plotter
def open_bare(app, rig, render_size, camera):
    import pyvista as pv
    import vtk
    from PyQt5 import QtWidgets
    from pyvistaqt import QtInteractor

    from rigedit.render.scene import faces_to_vtk

    win = QtWidgets.QMainWindow()
    plotter = QtInteractor(win, multi_samples=0, auto_update=False)
    win.setCentralWidget(plotter)
    mesh = pv.PolyData(rig.vertices.astype(np.float32).copy(), faces_to_vtk(rig.faces))
    # Rest normals as VTK computes them (what the editor shows in the rest pose).
    rest = mesh.compute_normals(point_normals=True, cell_normals=False, split_vertices=False,
                                consistent_normals=False, auto_orient_normals=False)
    rig.binding.bind_normals(rest.point_data["Normals"])
    mesh.point_data["Normals"] = np.asarray(rest.point_data["Normals"], dtype=np.float32)
    mesh.point_data.active_normals_name = "Normals"
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputData(mesh)
    mapper.ScalarVisibilityOff()
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    prop = actor.GetProperty()
    prop.SetInterpolationToGouraud()
    prop.SetSpecular(0.25)
    prop.SetSpecularPower(20)
    plotter.add_actor(actor, reset_camera=False)
    win.show()
    _pump(app)
    # Same render-area pixels as the editor's view.
    dw = render_size[0] - plotter.width()
    dh = render_size[1] - plotter.height()
    win.resize(win.width() + dw, win.height() + dh)
    _pump(app)
    plotter.renderer.GetActiveCamera().DeepCopy(camera)
    plotter.renderer.ResetCameraClippingRange()
    return win, plotter, mesh


def skin_into(rig, mesh, palette):
    """Skin positions and normals in one pass and write them into ``mesh`` in place (as
    the scene does, :func:`rigedit.render.proxy.write_skin`)."""
    from rigedit.render.proxy import write_skin

    write_skin(mesh, *rig.binding.skin_with_normals(palette))


def bare_frames(rig, plotter, mesh, palettes):
    """Median ms of a bare frame (skin positions+normals, copy, render) and of its render."""
    rw = plotter.render_window
    frame, render = [], []
    for p in list(palettes[:3]) + list(palettes):
        t0 = time.perf_counter()
        skin_into(rig, mesh, p)
        t1 = time.perf_counter()
        rw.Render()
        t2 = time.perf_counter()
        frame.append(t2 - t0)
        render.append(t2 - t1)
    frame, render = np.array(frame[3:]) * 1e3, np.array(render[3:]) * 1e3
    return float(np.median(frame)), float(np.median(render))


def bare_qt_frames(app, rig, plotter, mesh, palettes):
    """Median ms of a bare frame as a pyvistaqt application shows it: skin positions and
    normals, write them in place, ask the widget to repaint and let Qt paint (VTK's render,
    the blit into the widget and Qt's compositing of the window), and renders per frame."""
    rw = plotter.render_window
    count = [0]
    obs = rw.AddObserver("EndEvent", lambda *a: count.__setitem__(0, count[0] + 1))
    frame = []
    LAST_CPU.clear()
    for k, p in enumerate(list(palettes[:3]) + list(palettes)):
        if k == 3:
            count[0] = 0
            LAST_CPU.clear()
        t0, c0 = time.perf_counter(), time.process_time()
        skin_into(rig, mesh, p)
        plotter.update()
        app.processEvents()
        frame.append(time.perf_counter() - t0)
        LAST_CPU.append(time.process_time() - c0)
    rw.RemoveObserver(obs)
    return float(np.median(frame[3:]) * 1e3), count[0] / len(palettes)


def playback(app, w, frames=60, fps=30.0):
    """Median ms of a playback frame in the editor (the timeline's tick while playing: the
    clip's time set, the pose sampled and shown, the ruler's cursor and the panels refreshed,
    one paint), over the walk (or the current clip), and renders per frame."""
    d = w.document
    if "walk" in d.clips:
        d.set_current_clip("walk")
    duration = d.clips[d.current_clip].duration
    rw = w.plotter.render_window
    count = [0]
    obs = rw.AddObserver("EndEvent", lambda *a: count.__setitem__(0, count[0] + 1))
    per = []
    LAST_CPU.clear()
    # playing, as after the Play button (the panels know it), but stepped here frame by frame
    # instead of by the timeline's timer
    w.timeline.play()
    w.timeline.timer.stop()
    for i in range(frames + 3):
        if i == 3:
            count[0] = 0
            LAST_CPU.clear()
        t0, c0 = time.perf_counter(), time.process_time()
        w.timeline.set_time((i / fps) % duration)
        app.processEvents()
        per.append(time.perf_counter() - t0)
        LAST_CPU.append(time.process_time() - c0)
    w.timeline.pause()
    rw.RemoveObserver(obs)
    return float(np.median(per[3:]) * 1e3), count[0] / frames


def drag_palettes(rig, n=60):
    """Skinning palettes of ``n`` IK poses along bench_drag's loop of drag targets."""
    from rigedit.model.ik import drag_joint
    from rigedit.model.kinematics import skinning_matrices

    sk = rig.skeleton
    j, start, targets = drag_targets(rig, n)
    snap = start.as_array()
    work = start.copy()
    out = []
    for target in targets:
        work.set_array(snap)
        drag_joint(sk, work, j, target, chain_length=2, fk=rig.joint_matrices)
        out.append(skinning_matrices(sk, rig.joint_matrices(work)))
    return out


# ---------------------------------------------------------------------------- start-up
def first_frame_child():
    """Run app.py's main; at the end of the window's first render print the time since this
    process's Python code started and leave at once."""
    import app as app_module
    from rigedit.ui import main_window

    original = main_window.MainWindow.__init__

    def init(self, *a, **k):
        original(self, *a, **k)

        def done(*_):
            has_mesh = self.scene is not None and self.scene.mesh_actor is not None
            print(f"FIRST_FRAME {time.perf_counter() - T_START:.3f} mesh={has_mesh},"
                  f"visible={self.isVisible()}", flush=True)
            os._exit(0)
        self.plotter.render_window.AddObserver("EndEvent", done)

    main_window.MainWindow.__init__ = init
    app_module.main([])


def startup(runs=3):
    rows = []
    for _ in range(runs):
        t0 = time.perf_counter()
        res = subprocess.run([sys.executable, __file__, "--first-frame-child"],
                             capture_output=True, text=True, cwd=ROOT, timeout=120)
        whole = time.perf_counter() - t0
        line = next((ln for ln in res.stdout.splitlines() if ln.startswith("FIRST_FRAME")), None)
        if line is None:
            raise RuntimeError(f"no first frame: {res.stdout}\n{res.stderr}")
        rows.append((whole, float(line.split()[1]), line.split()[2]))
    return rows


# ---------------------------------------------------------------------------- main
def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", default="1280x720", help="editor window size")
    parser.add_argument("--moves", type=int, default=120)
    parser.add_argument("--profile-top", type=int, default=0,
                        help="also print the drag profile's N costliest functions")
    parser.add_argument("--startup", action="store_true", help="also time app.py start-up")
    parser.add_argument("--rounds", type=int, default=5,
                        help="interleaved rounds of the ratio table (r)")
    parser.add_argument("--no-layers", action="store_true",
                        help="skip the layer table (c) and the pipeline timings")
    parser.add_argument("--first-frame-child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.first_frame_child:
        return first_frame_child()
    from threadpoolctl import threadpool_limits

    threadpool_limits(1)
    from PyQt5 import QtWidgets

    import rigedit

    from rigedit.model import skinning_kernels

    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication([])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig = rigedit.load_rig(None)
    # the compiled kernels, as app.py loads them half a second after start (both plotters)
    kernels = skinning_kernels.load()
    print(f"skinning kernels: {'compiled' if kernels is not None else 'numpy'}")
    print(f"rig: {rig.name}, {len(rig.vertices):,} vertices, {len(rig.faces):,} triangles, "
          f"{len(rig.skeleton)} joints; load average {os.getloadavg()[0]:.2f} at start")
    size = tuple(int(v) for v in args.size.split("x"))
    w = open_editor(app, rig, size)
    render_size = (w.plotter.width(), w.plotter.height())
    rw_size = tuple(w.plotter.render_window.GetSize())
    print(f"editor window {args.size}: 3D view widget {render_size[0]}x{render_size[1]}, "
          f"render window {rw_size[0]}x{rw_size[1]} px")
    camera = w.plotter.renderer.GetActiveCamera()
    bwin, bplot, bmesh = open_bare(app, rig, render_size, camera)
    print(f"bare plotter render window {tuple(bplot.render_window.GetSize())} px")
    palettes = drag_palettes(rig)
    bare1 = bare_frames(rig, bplot, bmesh, palettes)
    j = _limb_joint(rig.skeleton)
    per_move, renders, invoke = drag(app, w, j, args.moves)
    bare2 = bare_frames(rig, bplot, bmesh, palettes)
    prof = cProfile.Profile()
    per_move_p, _, _ = drag(app, w, j, args.moves, profile=prof)
    bare_frame = min(bare1[0], bare2[0])
    bare_render = min(bare1[1], bare2[1])
    drag_ms = float(np.median(per_move))
    # the ratios of issue 12, interleaved: bare frame through Qt, editor drag, editor playback
    ratio_rows = {"bare": [], "bare render": [], "drag": [], "play": []}
    cpu_rows = {"bare": [], "drag": [], "play": []}

    def cpu():
        return float(np.median(LAST_CPU) * 1e3)
    for _ in range(args.rounds):
        ratio_rows["bare"].append(bare_qt_frames(app, rig, bplot, bmesh, palettes[:30]))
        cpu_rows["bare"].append(cpu())
        ratio_rows["bare render"].append((bare_frames(rig, bplot, bmesh, palettes[:30])[1], 1))
        ratio_rows["drag"].append((float(np.median(drag(app, w, j, 40)[0])), 1.0))
        cpu_rows["drag"].append(cpu())
        ratio_rows["play"].append(playback(app, w, frames=40))
        cpu_rows["play"].append(cpu())
    print(f"\n(a) bare plotter, skinned mesh only: frame {bare1[0]:.1f} / {bare2[0]:.1f} ms "
          f"(before / after the drag), of which render {bare1[1]:.1f} / {bare2[1]:.1f} ms")
    print(f"(b) editor drag: median {drag_ms:.1f} ms per mouse move (p90 "
          f"{np.percentile(per_move, 90):.1f}), {len(renders) / args.moves:.2f} renders per move, "
          f"render median {np.median(renders):.1f} ms; {1e3 / drag_ms:.1f} frames/s; "
          f"{drag_ms / bare_frame:.2f}x the bare frame without Qt's paint ({drag_ms / bare_render:.2f}x "
          f"its render); issue 12's ratio is the (r) rows' (both through Qt)")
    med = {k: float(np.median([r[0] for r in v])) for k, v in ratio_rows.items()}
    spread = {k: (min(r[0] for r in v), max(r[0] for r in v)) for k, v in ratio_rows.items()}
    print(f"\n(r) in {args.rounds} interleaved rounds (median of the round medians, "
          f"rounds' range):")
    for k, label in (("bare render", "bare plotter, render alone"),
                     ("bare", "bare plotter frame through Qt (skin, update, paint)"),
                     ("drag", "editor drag frame (one mouse move)"),
                     ("play", "editor playback frame (timeline tick of the walk)")):
        extra = "" if k.startswith("bare") else (
            f"  = {med[k] / med['bare']:.2f}x the bare frame, "
            f"{med[k] / med['bare render']:.2f}x its render alone")
        renders = np.mean([r[1] for r in ratio_rows[k]])
        print(f"    {label:<52} {med[k]:6.1f} ms ({spread[k][0]:.1f}-{spread[k][1]:.1f}; "
              f"{renders:.2f} renders/frame){extra}")
    c = {k: float(np.median(v)) for k, v in cpu_rows.items()}
    print(f"    CPU time of this process per frame (median of the rounds): bare {c['bare']:.1f} "
          f"ms, drag {c['drag']:.1f} ms = {c['drag'] / c['bare']:.2f}x, playback "
          f"{c['play']:.1f} ms = {c['play'] / c['bare']:.2f}x")
    print(f"    of a move: VTK event (widget + handler + render) {np.median(invoke):.1f} ms, "
          f"Qt processEvents after it {np.median(per_move - invoke):.1f} ms")
    print(f"    same drag under cProfile: median {np.median(per_move_p):.1f} ms per move")
    for label, ms in profile_rows(prof, args.moves):
        print(f"    {label:<48} {ms:7.2f} ms/frame")
    if args.profile_top:
        pstats.Stats(prof).sort_stats("tottime").print_stats(args.profile_top)
    if not args.no_layers:
        print("\n(c) the editor's pipeline, timed alone on the dragged pose")
        for label, ms in pipeline_costs(w):
            print(f"    {label:<58} {ms:7.2f} ms")
        print("    static re-render of the same pose (no data changed), layers hidden in turn")
        ren = w.plotter.renderer
        print(f"    (depth peeling {bool(ren.GetUseDepthPeeling())}, layers "
              f"{w.plotter.render_window.GetNumberOfLayers()}, renderers "
              f"{w.plotter.render_window.GetRenderers().GetNumberOfItems()})")
        rows = layer_costs(app, w)
        full = rows[0][1]
        for label, ms, (lo, hi) in rows:
            print(f"    {label:<58} {ms:7.2f} ms  (saves {full - ms:5.1f}; "
                  f"rounds {lo:.1f}-{hi:.1f})")
        for k, v in layer_triangles(w).items():
            print(f"    {k:<20} {v}")
        bare3 = bare_frames(rig, bplot, bmesh, palettes)
        print(f"bare plotter again after the layer table: frame {bare3[0]:.1f} ms, render "
              f"{bare3[1]:.1f} ms")
    print(f"load average after the run: {os.getloadavg()}")
    w.close()
    bwin.close()
    if args.startup:
        print("\n(d) start-up: app.py (quadruped, 1440x900) to the end of the first render")
        for whole, inner, mesh in startup():
            print(f"    whole process {whole:.2f} s, Python code start to first frame "
                  f"{inner:.2f} s ({mesh})")
        print(f"load average: {os.getloadavg()}")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except Exception:  # the editor's exception hook would swallow it
        import traceback

        traceback.print_exc()
        sys.exit(1)
