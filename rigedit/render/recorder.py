"""Off-screen recording of a clip to MP4 (H.264, yuv420p) or GIF.

The recorder builds its own off-screen plotter and :class:`RigScene` and samples a private copy
of the clip, so it shares no mutable state with an interactive view; frame ``i`` shows the
clip at exactly ``t = start + i / fps``. The file is written under a temporary name beside the
target and renamed over it at the end, so a cancelled or failed recording leaves any existing
file untouched.

Per frame the recorder skins the mesh (positions and normals in one pass), moves the camera,
renders, reads the pixels into a reused buffer (:class:`~rigedit.render.video_writer.FrameReader`)
and queues them for a writer thread that feeds ffmpeg
(:mod:`rigedit.render.video_writer`), whose one encoding thread runs beside the next render
(README, Speed > Recording, for the measured rates). The camera's framing is
:mod:`rigedit.render.camera`'s.
"""
from __future__ import annotations

import inspect
import os
import sys
import warnings
from pathlib import Path

import numpy as np
import pyvista as pv

from ..errors import RigFileError
from ..io.atomic import check_output_folder, write_error
from ..progress import Cancelled
from .camera import apply_camera, figure_joints, horizontal, swept_points, turn_about
from .floor import GRID_COLOR
from .scene import RigScene
from .video_writer import FrameReader, RecordingCancelled, ThreadedWriter, VideoWriter

__all__ = ["record_clip", "frame_times", "VIDEO_SUFFIXES", "RecordingCancelled"]

VIDEO_SUFFIXES = (".mp4", ".gif")
#: One colour: a gradient is a full-frame quad in software OpenGL (about 6 ms a 1280x720 frame)
BACKGROUND = "#dadfe5"


def frame_times(duration, fps, start=0.0):
    """(N,) sample times ``start + i / fps`` for ``N = round(duration * fps)`` frames (at least
    one). A looping clip's last frame is then one step before the loop point, which equals
    frame 0, so a looped video has no doubled frame."""
    if fps <= 0:
        raise ValueError(f"expected fps > 0, got {fps}")
    n = max(1, int(round(duration * fps)))
    return start + np.arange(n) / float(fps)


def _checked_size(path, size):
    """``(width, height)`` of a video ``path`` may hold, or one error saying why not."""
    if path.suffix.lower() not in VIDEO_SUFFIXES:
        raise RigFileError(path, f"expected a video file name ending in "
                                 f"{' or '.join(VIDEO_SUFFIXES)}, got {path.suffix or 'none'}")
    width, height = (int(s) for s in size)
    if width < 16 or height < 16:
        raise ValueError(f"expected a frame size of at least 16x16, got {width}x{height}")
    if path.suffix.lower() == ".mp4" and (width % 2 or height % 2):
        raise ValueError(f"H.264 yuv420p needs even sizes, got {width}x{height}")
    return width, height


def record_clip(rig, clip, path, fps=30, duration=None, size=(1280, 720), start=0.0,
                view="front", angle=0.0, camera=None, orbit=0.0, follow_root=True,
                show_skeleton=False, multi_samples=0, quality=7, progress=None,
                show_floor=True, preset="veryfast", skinning="lbs"):
    """Render ``clip`` on ``rig`` off-screen into a video file.

    Parameters
    ----------
    rig : Rig
    clip : Clip or None
        None records the rest pose. A copy is sampled, so the caller may keep editing.
    path : str or Path
        ``.mp4`` (H.264, yuv420p) or ``.gif``. Written atomically.
    fps : float
    duration : float, optional
        Seconds to record; the clip's duration when omitted.
    size : (int, int)
        Width and height in pixels (even numbers for MP4).
    start : float
        Clip time of the first frame.
    view, angle :
        Camera preset and turn about the vertical axis in degrees (see ``RigScene.view``).
    camera : dict, optional
        ``{"position", "focal_point", "up"}`` and optionally ``"view_angle"``,
        ``"parallel_projection"``, ``"parallel_scale"`` to copy (the editor's current view);
        overrides ``view``/``angle``.
    orbit : float
        Degrees the camera turns about the vertical axis over the recording.
    follow_root : bool
        Move the camera with the figure root's horizontal motion (walks stay in frame): the
        hips when a carrier root carries them (:func:`rigedit.render.camera.figure_joints`).
    show_skeleton, show_floor : bool
    multi_samples : int
        Anti-aliasing samples (0 is several times faster in software OpenGL).
    quality : int
        imageio-ffmpeg quality 0-10 for MP4.
    preset : str
        x264 preset. The default ``veryfast`` (with a shorter lookahead and simpler
        sub-pixel search, :class:`~rigedit.render.video_writer.VideoWriter`) keeps the
        encoder's CPU small beside the render's; ``medium`` gives smaller files slower.
    skinning : {"lbs", "dqs"}
        Linear blend or dual-quaternion skinning.
    progress : callable(fraction, stage), optional
        :mod:`rigedit.progress`'s protocol: called after each frame with the fraction of
        frames done and the stage ``"record"``; raising :class:`rigedit.progress.Cancelled`
        cancels (``RecordingCancelled``, a ``Cancelled``, comes out). Deprecated but still
        taken: the older ``progress(done, total) -> bool`` (no parameter named ``stage``),
        called with the frames done and the total, whose False cancels.

    Returns
    -------
    frames : int
        Frames written.

    Raises
    ------
    RigFileError
        Bad suffix or missing folder.
    ValueError
        Bad size or frame rate.
    RecordingCancelled
        When ``progress`` cancelled; no file is left behind (an existing one is kept).

    Notes
    -----
    Over 80 lines for this docstring of eighteen options; the body (under 70) is set-up, then
    one frame loop that keeps the pose, the camera and the writer side by side.
    """
    path = Path(path)
    width, height = _checked_size(path, size)
    if duration is None:
        duration = clip.duration if clip is not None and clip.duration > 0 else 1.0
    times = frame_times(duration, fps, start)
    check_output_folder(path)
    if clip is not None:
        clip = clip.copy()   # the editor may change its clip while we render

    after_frame = _frame_callback(progress)
    shown_weights = rig.binding.morph_weights
    _use_egl_without_display()
    plotter = pv.Plotter(off_screen=True, window_size=(width, height))
    writer = None
    try:
        plotter.enable_anti_aliasing("msaa", multi_samples=multi_samples) if multi_samples \
            else plotter.disable_anti_aliasing()
        plotter.set_background(BACKGROUND)
        # normals skinned with the vertices: no normals filter over the mesh each frame
        scene = RigScene(plotter, rig, show_skeleton=show_skeleton, show_floor=show_floor,
                         skinning=skinning, skinned_normals=True, floor_style="lines")
        _grid_floor(plotter)
        follow = figure_joints(rig, clip)[1]   # the hips, not a carrier root left behind
        if scene.floor is not None and clip is not None:
            # a floor under the whole travel, fixed, so the camera following the figure
            # shows it walking over the lines
            scene.floor.following = False
            scene.floor.reach(_travel(rig, clip, times, follow))
        pose = rig.rest_pose()
        if camera is not None:
            apply_camera(plotter.camera, camera)
        else:
            scene.view(view, angle, points=swept_points(rig, clip, times))
        if clip is not None:
            clip.sample(times[0], out=pose)
            rig.binding.set_morph_weights(clip.sample_morphs(times[0]))
        model0 = scene.update(pose)
        base_pos = np.array(plotter.camera.position)
        base_focal = np.array(plotter.camera.focal_point)
        root0 = model0[follow, :3, 3].copy()
        up = scene.up
        camera = plotter.camera
        # pyvista's render() does nothing until a first show() or screenshot()
        plotter.screenshot(return_img=False)
        depth = 2
        reader = FrameReader(plotter, buffers=depth + 2)
        writer = ThreadedWriter(VideoWriter(path, fps, quality, preset), depth, reader.image)
        for i, t in enumerate(times):
            if clip is not None:
                clip.sample(t, out=pose)
                # the clip's morph weights (the editor's are put back at the end)
                rig.binding.set_morph_weights(clip.sample_morphs(t))
            model = scene.update(pose)
            shift = horizontal(model[follow, :3, 3] - root0, up) if follow_root else \
                np.zeros(3)
            rel = base_pos - base_focal
            if orbit:
                rel = turn_about(rel, up, orbit * i / max(len(times), 1))
            # VTK's setters: pyvista's reset the clipping range (all actors' bounds) each
            camera.SetFocalPoint(*(base_focal + shift))
            camera.SetPosition(*(base_focal + shift + rel))
            plotter.renderer.ResetCameraClippingRange()
            plotter.render()
            writer.append(reader.read())
            if after_frame is not None:
                after_frame(i + 1, len(times))
        writer.commit()
        writer = None
        return len(times)
    except OSError as exc:   # ffmpeg or the disk failed: one line naming the user's video
        new = write_error(exc, path)
        if new is exc:
            raise
        raise new from None
    finally:
        rig.binding.set_morph_weights(shown_weights)
        if writer is not None:
            writer.abort()
        plotter.close()


def _travel(rig, clip, times, joint, samples=200):
    """(N, 3) positions of ``joint`` over the recorded ``times`` (at most ``samples`` of
    them, first and last included): where the figure goes."""
    pose = rig.rest_pose()
    pick = np.unique(np.linspace(0, len(times) - 1, min(samples, len(times))).round()
                     .astype(int))
    return np.array([rig.joint_matrices(clip.sample(times[i], out=pose))[joint, :3, 3]
                     for i in pick])


def _frame_callback(progress):
    """``after_frame(done, total)`` calling ``progress`` in its protocol (None for none),
    which raises :class:`RecordingCancelled` when the callable cancels.

    Both protocols take two arguments, so the older ``(done, total) -> bool`` is told apart
    by its signature: a callable with a parameter named ``stage`` (or ``*args``) follows
    :mod:`rigedit.progress`; any other callable of two arguments is the older one
    (``DeprecationWarning``; ``rigedit.ui.record_dialog`` passes it until it moves over).
    """
    if progress is None:
        return None
    if not _is_old_frame_callback(progress):
        def after_frame(done, total):
            try:
                progress(done / total, "record")
            except RecordingCancelled:
                raise
            except Cancelled as exc:  # callers catching RecordingCancelled still see it
                raise RecordingCancelled(f"recording cancelled after {done} frames") from exc
        return after_frame
    warnings.warn("record_clip's progress(done, total) -> bool is deprecated: take "
                  "progress(fraction, stage) and raise rigedit.progress.Cancelled to stop",
                  DeprecationWarning, stacklevel=3)

    def after_frame_old(done, total):
        if progress(done, total) is False:
            raise RecordingCancelled(f"recording cancelled after {done} frames")
    return after_frame_old


def _is_old_frame_callback(progress):
    try:
        params = inspect.signature(progress).parameters.values()
    except (TypeError, ValueError):  # no signature to read: take it as the protocol
        return False
    return not any(p.name == "stage" or p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
                   for p in params)


def _use_egl_without_display():
    """With no X display (a server, CI without Xvfb), VTK first tries X, prints a warning and
    then falls back; asking for its EGL window directly renders the same frames silently.
    Only set when nothing chose otherwise."""
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY")
                                                 or os.environ.get("WAYLAND_DISPLAY")):
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")


def _grid_floor(plotter, behind=BACKGROUND):
    """The floor's grid lines (the scene's "lines" floor) in one colour pre-blended with the
    colour they show over. Filling the floor plane is what costs in software OpenGL: measured
    at 1280x720 on the quadruped, 14 frames/s with the filled translucent floor against 21
    with its lines only and 24 with no floor."""
    actor = plotter.actors.get("rig-grid")
    if actor is None:
        return
    bg = np.array(pv.Color(behind).float_rgb)
    alpha = 0.7  # a little stronger than in the editor: the recorder has no floor plane
    prop = actor.GetProperty()
    prop.SetColor(*(alpha * np.array(pv.Color(GRID_COLOR).float_rgb) + (1 - alpha) * bg))
    prop.LightingOn()   # as before: ambient only, so the pixels stay the same
    prop.SetAmbient(1.0)
    prop.SetDiffuse(0.0)
    prop.SetSpecular(0.0)
