"""Recording throughput: frames per second of ``record_clip`` at 1280x720, beside a bare
off-screen plotter that only skins, draws and reads back the same mesh.

Run under a display (``xvfb-run -a .venv/bin/python benchmarks/bench_record.py``). Uses the
bundled quadruped's walk (``rigedit.load_rig()``), or a code-built creature when the assets are
not installed. In one run, ``--repeat`` times in turn (so both see the same load):

* bare: a ``pyvista.Plotter(off_screen=True)`` of the same size, multi-sampling off, pyvista's
  default lights, the mesh added once with the recorder's material; per frame the same clip
  sample, ``binding.skin_with_normals`` (positions and normals in one pass) written into the
  mesh in place, ``render()`` and a read-back of the pixels into a reused buffer
  (``vtkRenderWindow.GetPixelData``, as ``screenshot`` reads them), no encoding; the camera
  framed as the recorder frames it;
* record_clip: the whole recorder (MP4 H.264 veryfast, floor grid, camera follow, encode), its
  plotter's set-up included.

Prints the best rate, the spread (worst-best) and the process CPU time per frame (this
process with its threads, llvmpipe's included; ffmpeg runs in its own), then the ratio
achieved / bare. record_clip's rate counts the whole call (plotter, scene and ffmpeg set-up,
framing, closing the file); the line under it counts its frame loop alone (from the first
frame's progress call to the last), as the bare plotter's rate does. The bare plotter's rate
counting its own set-up (plotter, mesh, first render, close) is printed too, and the ratios
loop to loop and whole call to whole call. Then record_clip's set-up
(to the end of its first frame) and the time after its last frame (ffmpeg's flush), and the
CPU-bound ratio: the bare plotter's CPU per frame over record_clip's plus ffmpeg's, the rate
ratio to expect when other jobs keep every core busy (the wall-rate ratio then swings with
how the scheduler shares the cores between the processes). ``--configs`` adds the
older table's other settings (medium preset, no floor, 4x MSAA, GIF). ``--compare-with
OLD.py`` also times another version of ``rigedit/render/recorder.py`` in the same run (for
example ``git show COMMIT:rigedit/render/recorder.py > /tmp/old_recorder.py``).
"""
from __future__ import annotations

import argparse
import os
import resource
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")


def load():
    import rigedit

    try:
        rig = rigedit.load_rig()
    except (ValueError, OSError):
        from rigedit.ui.fallback import demo_rig

        rig = demo_rig()
    clip = rig.clips.get("walk") or next(iter(rig.clips.values()), None)
    return rig, clip


def bare(rig, clip, frames, fps, size):
    """Frames/s and CPU s/frame of a plotter that skins, draws and reads back the mesh only."""
    import numpy as np
    import pyvista as pv

    from rigedit.model.kinematics import skinning_matrices
    from rigedit.model.skinning import vertex_normals
    from rigedit.render.mesh_look import MESH_COLOR
    from rigedit.render.proxy import faces_to_vtk, write_skin
    from rigedit.render.video_writer import FrameReader

    binding = rig.binding
    binding.bind_normals(vertex_normals(binding.rest_vertices, rig.faces))
    mesh = pv.PolyData(rig.vertices.astype(np.float32), faces_to_vtk(rig.faces))
    mesh.point_data.set_array(np.zeros((len(rig.vertices), 3), np.float32), "Normals")
    mesh.point_data.active_normals_name = "Normals"
    w0 = time.perf_counter()
    plotter = pv.Plotter(off_screen=True, window_size=size)
    try:
        plotter.disable_anti_aliasing()
        plotter.add_mesh(mesh, color=MESH_COLOR, smooth_shading=True, specular=0.25,
                         specular_power=20)
        pose = rig.rest_pose()
        times = np.arange(frames) / float(fps)
        frame_like_the_recorder(plotter, rig, clip, frames, fps)
        plotter.screenshot(return_img=False)  # pyvista renders only after a first one
        reader = FrameReader(plotter, buffers=1)
        t0, c0 = time.perf_counter(), time.process_time()
        for t in times:
            if clip is not None:
                clip.sample(t, out=pose)
            palette = skinning_matrices(rig.skeleton, rig.joint_matrices(pose))
            write_skin(mesh, *binding.skin_with_normals(palette))
            plotter.render()
            img = reader.read()
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        assert img.shape[:2] == (size[1], size[0])
    finally:
        plotter.close()
    bare_whole.append(frames / (time.perf_counter() - w0))
    return frames / wall, cpu / frames


def frame_like_the_recorder(plotter, rig, clip, frames, fps):
    """The recorder's camera (front view fitted to the vertices the clip sweeps), so both
    plotters fill the same pixels; the walk's root travel over 2 s is small at that size."""
    from rigedit.render.camera import frame_view, front_vector, swept_points, up_vector
    from rigedit.render.recorder import frame_times

    times = frame_times(frames / fps, fps)
    frame_view(plotter, up_vector(rig.up), front_vector(rig.up),
               swept_points(rig, clip, times), "front")


encoder_cpu = []   # ffmpeg's CPU seconds per frame (children of this process), per call
bare_whole = []    # the bare plotter's rate counting its set-up (plotter, first render, close)


def recorded(rig, clip, path, frames, fps, size, module=None, **options):
    if module is None:
        from rigedit.render.recorder import record_clip
    else:
        record_clip = module.record_clip
    stamps = []
    f0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0, c0 = time.perf_counter(), time.process_time()
    n = record_clip(rig, clip, path, fps=fps, duration=frames / fps, size=size,
                    progress=lambda done, total: stamps.append(
                        (time.perf_counter(), time.process_time())), **options)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    f1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if Path(path).suffix == ".mp4":   # a GIF is written by this process
        encoder_cpu.append((f1.ru_utime + f1.ru_stime - f0.ru_utime - f0.ru_stime) / n)
    (w1, c1), (w2, c2) = stamps[0], stamps[-1]
    loop = ((n - 1) / (w2 - w1), (c2 - c1) / (n - 1))
    # seconds to the end of the first frame, and after the last one
    edge = (w1 - t0, t0 + wall - w2)
    return (n / wall, cpu / n), loop, edge


def summary(rates):
    fps = [r for r, _ in rates]
    cpu = min(c for _, c in rates)
    return max(fps), max(fps) - min(fps), cpu


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=60)
    ap.add_argument("--fps", type=float, default=30)
    ap.add_argument("--size", type=int, nargs=2, default=(1280, 720))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--configs", action="store_true", help="also the other settings")
    ap.add_argument("--compare-with", metavar="RECORDER.py",
                    help="another version of rigedit/render/recorder.py, timed alongside")
    args = ap.parse_args(argv)
    rig, clip = load()
    size = tuple(args.size)
    print(f"{rig.name}: {len(rig.vertices):,} vertices, {len(rig.faces):,} triangles, "
          f"{len(rig.skeleton)} joints; clip {clip.name if clip else None}; "
          f"{size[0]}x{size[1]}, {args.frames} frames, {args.repeat} runs each, interleaved; "
          f"load average {os.getloadavg()[0]:.1f}")
    configs = [("record_clip MP4 H.264 veryfast", ".mp4", {})]
    if args.configs:
        configs += [("record_clip MP4 medium preset", ".mp4", {"preset": "medium"}),
                    ("record_clip MP4, no floor", ".mp4", {"show_floor": False}),
                    ("record_clip MP4, 4x MSAA", ".mp4", {"multi_samples": 4}),
                    ("record_clip GIF", ".gif", {})]
    if args.compare_with:
        import importlib.util

        spec = importlib.util.spec_from_file_location("rigedit.render._compared_recorder",
                                                      args.compare_with)
        other = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(other)
        configs.append((f"record_clip of {Path(args.compare_with).name}", ".mp4",
                        {"module": other}))
    runs = {label: [] for label in ["bare plotter (skin, draw, read back)"]
            + [c[0] for c in configs]}
    bare(rig, clip, 5, args.fps, size)  # warm-up: kernels, GL context
    edges = []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.repeat):
            runs["bare plotter (skin, draw, read back)"].append(
                bare(rig, clip, args.frames, args.fps, size))
            for label, suffix, options in configs:
                path = Path(tmp) / f"bench{suffix}"
                whole, loop, edge = recorded(rig, clip, path, args.frames, args.fps, size,
                                             **options)
                runs[label].append(whole)
                # the default configuration's set-up, close and ffmpeg CPU per frame
                edges.append(edge + (encoder_cpu[-1],)) if label == configs[0][0] else None
                runs.setdefault(f"  frames 2-{args.frames} only", []).append(loop) \
                    if label == configs[0][0] else None
    order = list(runs)
    loop_label = f"  frames 2-{args.frames} only"
    order.insert(2, order.pop(order.index(loop_label)))
    print(f"  {'':40s} {'best':>7s} {'spread':>7s} {'CPU/frame':>10s}")
    for label, rates in sorted(runs.items(), key=lambda kv: order.index(kv[0])):
        best, spread, cpu = summary(rates)
        print(f"  {label:40s} {best:7.1f} {spread:7.1f} {cpu * 1e3:8.1f} ms   frames/s")
    b = summary(runs["bare plotter (skin, draw, read back)"])
    r = summary(runs[configs[0][0]])
    lp = summary(runs[loop_label])
    print(f"  bare plotter counting its set-up and close: {max(bare_whole[1:]):.1f} frames/s (best)")
    print(f"  ffmpeg's own CPU time per frame (its process): "
          f"{min(encoder_cpu) * 1e3:.1f}-{max(encoder_cpu) * 1e3:.1f} ms")
    print(f"  achieved / bare, frame loops: {lp[0] / b[0]:.2f}; whole calls (set-ups "
          f"counted on both sides): {r[0] / max(bare_whole[1:]):.2f}; record_clip's whole call / "
          f"bare loop: {r[0] / b[0]:.2f} (best rates)")
    print(f"  CPU per frame "
          f"{r[2] / b[2]:.2f}x the bare plotter's (load average now "
          f"{os.getloadavg()[0]:.1f})")
    first, last = (min(e[k] for e in edges) for k in (0, 1))
    print(f"  record_clip's set-up to the first frame's end {first:.2f} s, after the last frame "
          f"(ffmpeg's flush, closing) {last:.2f} s (best)")
    # when every core is busy (other jobs), rates follow CPU time: the bare plotter's CPU per
    # frame over the recorder's plus ffmpeg's is the ratio a CPU-bound machine allows
    print(f"  CPU-bound ratio bare CPU / (record_clip CPU + ffmpeg CPU) per frame: "
          f"{b[2] / (r[2] + min(e[2] for e in edges)):.2f}")


if __name__ == "__main__":
    main()
