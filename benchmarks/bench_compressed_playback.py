"""The editor's playback step on a compressed clip against the same clip uncompressed.

Issue 20: "a compressed clip plays in the editor at the same frame rate as the original".
The step is what the editor does per played frame: ``Document.set_time(t)`` (the clip
sampled into the document's pose: a plain :class:`~rigedit.animation.clip.Clip`'s tracks, or
a :class:`~rigedit.compression.CompressedClip` decoded from its bits), forward kinematics,
skinning and the view's update (``RigScene.update_from_matrices``: the mesh's points, the
bones, the floor), then one render of an off-screen ``pyvista.Plotter`` at 1280x720.

The compressed clip is the original compressed with :class:`rigedit.editor.compression
.CompressedExport` (``--max-error`` cm, 3 cm shell) into a ``.rgc`` file and read back with
``rigedit.load_rig``, as File > Open reads it. Both clips are on one rig and one scene; the
rounds alternate (original, compressed, original, ...) so both see the same load. Each clip's
decoder and the skinning kernels are warmed up first (the compressed clip imports its numba
decoder on its first sample, ~1 s, once per process).

Prints, per clip, the median and best milliseconds per step over ``--rounds`` rounds of
``--frames`` frames, the sampling alone (``clip.sample``) per clip, and the ratios
compressed / original; and the original's step with View > Compare compressed on (the
preview's ``at(t)`` and the overlay's update and text each frame), against it off. Run under a display or with OSMesa:
``xvfb-run -a .venv/bin/python benchmarks/bench_compressed_playback.py``.
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time
import warnings
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")


def setup(rig_name, clip_name, max_error_cm):
    import pyvista as pv

    import rigedit
    from rigedit.editor.compression import export_compressed
    from rigedit.editor.document import Document
    from rigedit.render.scene import RigScene

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig = rigedit.load_rig(rig_name)
    doc = Document(rig)
    with tempfile.TemporaryDirectory(prefix="bench-rgc-") as folder:
        path = Path(folder) / "clip.rgc"
        report = export_compressed(doc, path, max_error_cm / 100, clips=[clip_name])
        packed = rigedit.load_rig(path).clips[clip_name]   # read whole: the file can go
    plotter = pv.Plotter(off_screen=True, window_size=(1280, 720))
    scene = RigScene(plotter, rig)   # built on the plain clips (it reads their tracks)
    scene.view("front", angle=35)
    compressed_name = f"{clip_name}-compressed"
    rig.clips[compressed_name] = packed
    return doc, scene, plotter, {"original": clip_name, "compressed": compressed_name}, report


def step_loop(doc, scene, plotter, times, compare=None):
    """Seconds per playback step over ``times`` (``compare``: (preview, overlay) drawn too,
    as View > Compare compressed does on each time change)."""
    start = time.perf_counter()
    for t in times:
        doc.set_time(t)
        scene.update_from_matrices(doc.rig.joint_matrices(doc.pose))
        if compare is not None:
            preview, overlay = compare
            positions, errors = preview.at(t)
            overlay.update(positions, errors)
            overlay.set_text(preview.summary(errors))
        plotter.render()
    return (time.perf_counter() - start) / len(times)


def comparison(doc, scene, plotter, name, max_error):
    """View > Compare compressed's preview of clip ``name`` and its overlay."""
    from rigedit.editor.compression import CompressedPreview
    from rigedit.render.compare_overlay import CompareOverlay

    doc.set_current_clip(name)
    preview = CompressedPreview(doc, max_error)
    preview.refresh()
    positions, errors = preview.at(0.0)
    overlay = CompareOverlay(plotter, positions, doc.skeleton.parents, errors, max_error,
                             0.02, scene.carriers)
    return preview, overlay


def sample_loop(clip, pose, times):
    start = time.perf_counter()
    for t in times:
        clip.sample(t, out=pose)
    return (time.perf_counter() - start) / len(times)


def main(argv=None):
    import numpy as np

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rig", default="quadruped")
    ap.add_argument("--clip", default="walk")
    ap.add_argument("--max-error", type=float, default=0.01, metavar="CM")
    ap.add_argument("--frames", type=int, default=120)
    ap.add_argument("--rounds", type=int, default=7)
    args = ap.parse_args(argv)
    doc, scene, plotter, names, report = setup(args.rig, args.clip, args.max_error)
    rig = doc.rig
    duration = rig.clips[names["original"]].duration
    times = (np.arange(args.frames) / 30.0) % max(duration, 1e-6)
    steps = {k: [] for k in (*names, "compare")}
    samples = {k: [] for k in names}
    pose = rig.rest_pose()
    for name in names.values():   # warm-up: decoders, kernels, the first renders
        doc.set_current_clip(name)
        step_loop(doc, scene, plotter, times[:10])
    compare = comparison(doc, scene, plotter, names["original"], args.max_error / 100)
    for _ in range(args.rounds):
        for kind, name in names.items():
            doc.set_current_clip(name)
            steps[kind].append(step_loop(doc, scene, plotter, times))
            samples[kind].append(sample_loop(rig.clips[name], pose, times))
        doc.set_current_clip(names["original"])
        steps["compare"].append(step_loop(doc, scene, plotter, times, compare))
    print(f"{args.rig} {args.clip}: {len(rig.skeleton)} joints, {len(rig.vertices)} vertices, "
          f"{duration:g} s; compressed at {args.max_error:g} cm: {report.lines()[0]}")
    print(f"{args.rounds} rounds x {args.frames} frames, 1280x720 off-screen, "
          f"OMP_NUM_THREADS={os.environ['OMP_NUM_THREADS']}")
    for kind in steps:
        s = np.array(steps[kind]) * 1e3
        line = (f"  {kind:10s} step median {np.median(s):7.3f} ms, best {s.min():7.3f} ms "
                f"({1e3 / np.median(s):5.1f} steps/s)")
        if kind in samples:
            line += f"; clip.sample median {np.median(samples[kind]) * 1e6:7.1f} us"
        print(line + ("; the original with View > Compare compressed on" if kind == "compare"
                      else ""))
    ratio = np.median(steps["compressed"]) / np.median(steps["original"])
    best = min(steps["compressed"]) / min(steps["original"])
    sample = np.median(samples["compressed"]) / np.median(samples["original"])
    print(f"compressed / original: step {ratio:.3f} (median), {best:.3f} (best); "
          f"clip.sample alone {sample:.3f}")
    print(f"compare on / off: step {np.median(steps['compare']) / np.median(steps['original']):.3f}"
          f" (median)")
    plotter.close()


if __name__ == "__main__":
    main()
