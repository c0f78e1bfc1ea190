"""Off-screen recording of a clip to MP4 (H.264, yuv420p) or GIF.

The recorder builds its own off-screen plotter and :class:`RigScene` and samples a private copy
of the clip, so it shares no mutable state with an interactive view; frame ``i`` shows the
clip at exactly ``t = start + i / fps``. The file is written under a temporary name beside the
target and renamed over it at the end, so a cancelled or failed recording leaves any existing
file untouched.

Per frame the recorder skins the mesh (positions and normals in one pass), moves the camera,
renders, reads the pixels into a reused buffer (:class:`FrameReader`) and queues them for a
writer thread that feeds ffmpeg, whose one encoding thread runs beside the next render
(README, Speed > Recording, for the measured rates).
"""
from __future__ import annotations

import contextlib
import os
import queue
import sys
import threading
from pathlib import Path

import numpy as np
import pyvista as pv

from ..errors import RigFileError
from ..io.atomic import check_output_folder, naming_target, temp_beside
from .floor import GRID_COLOR
from .scene import RigScene, joint_points, turn_about, up_vector

__all__ = ["record_clip", "frame_times", "camera_state", "apply_camera", "VIDEO_SUFFIXES",
           "RecordingCancelled", "FrameReader"]

VIDEO_SUFFIXES = (".mp4", ".gif")
#: One colour: a gradient is a full-frame quad in software OpenGL (about 6 ms a 1280x720 frame)
BACKGROUND = "#dadfe5"


class RecordingCancelled(Exception):
    """The progress callback asked to stop; the partial file was removed."""


def frame_times(duration, fps, start=0.0):
    """(N,) sample times ``start + i / fps`` for ``N = round(duration * fps)`` frames (at least
    one). A looping clip's last frame is then one step before the loop point, which equals
    frame 0, so a looped video has no doubled frame."""
    if fps <= 0:
        raise ValueError(f"expected fps > 0, got {fps}")
    n = max(1, int(round(duration * fps)))
    return start + np.arange(n) / float(fps)


class _Writer:
    """Streams frames to ffmpeg (MP4) or collects palette frames (GIF) into a temporary file;
    :meth:`commit` renames it over the target."""

    def __init__(self, path, fps, quality, preset="veryfast"):
        import imageio.v2 as imageio

        self.path = Path(path)
        self.fps = fps
        self.gif = self.path.suffix.lower() == ".gif"
        fd, tmp = temp_beside(self.path, suffix=self.path.suffix)
        os.close(fd)
        self.tmp = Path(tmp)
        self.frames = []
        if not self.gif:
            try:
                # ffmpeg encodes in its own process while the next frame renders here
                self.writer = imageio.get_writer(
                    str(self.tmp), format="FFMPEG", mode="I", fps=fps, codec="libx264",
                    pixelformat="yuv420p", quality=quality, macro_block_size=2,
                    # one x264 thread: the render uses the other core (x264's default
                    # frame threads cost 1-2 ms more CPU a frame for the same file)
                    output_params=["-preset", preset, "-threads", "1"],
                    ffmpeg_log_level="error")
            except BaseException:   # Ctrl-C while ffmpeg starts: no writer to abort yet
                with contextlib.suppress(OSError):
                    self.tmp.unlink()
                raise

    def append(self, frame):
        if self.gif:
            from PIL import Image

            # one byte per pixel instead of three: a long GIF stays in memory until the end
            self.frames.append(Image.fromarray(frame[..., :3]).quantize(
                256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE))
        else:
            self.writer.append_data(frame)

    def commit(self):
        try:
            if self.gif:
                first, rest = self.frames[0], self.frames[1:]
                first.save(self.tmp, format="GIF", save_all=True, append_images=rest,
                           duration=int(round(1000.0 / self.fps)), loop=0, optimize=False)
                self.frames = []
            else:
                self.writer.close()
            os.replace(self.tmp, self.path)
        except OSError as exc:   # name the user's file, not the temporary one
            raise naming_target(exc, self.tmp, self.path) from None

    def abort(self):
        with contextlib.suppress(Exception):
            if not self.gif:
                self.writer.close()
        self.frames = []
        with contextlib.suppress(OSError):
            self.tmp.unlink()


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
        Move the camera with the root joint's horizontal motion (walks stay in frame).
    show_skeleton, show_floor : bool
    multi_samples : int
        Anti-aliasing samples (0 is several times faster in software OpenGL).
    quality : int
        imageio-ffmpeg quality 0-10 for MP4.
    preset : str
        x264 preset; ``veryfast`` keeps the encoder from being the bottleneck.
    skinning : {"lbs", "dqs"}
        Linear blend or dual-quaternion skinning.
    progress : callable(done, total) -> bool, optional
        Called after each frame; returning False cancels (raises ``RecordingCancelled``).

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
        When ``progress`` returned False; no file is left behind (an existing one is kept).
    """
    path = Path(path)
    if path.suffix.lower() not in VIDEO_SUFFIXES:
        raise RigFileError(path, f"expected a video file name ending in "
                                 f"{' or '.join(VIDEO_SUFFIXES)}, got {path.suffix or 'none'}")
    width, height = (int(s) for s in size)
    if width < 16 or height < 16:
        raise ValueError(f"expected a frame size of at least 16x16, got {width}x{height}")
    if path.suffix.lower() == ".mp4" and (width % 2 or height % 2):
        raise ValueError(f"H.264 yuv420p needs even sizes, got {width}x{height}")
    if duration is None:
        duration = clip.duration if clip is not None and clip.duration > 0 else 1.0
    times = frame_times(duration, fps, start)
    check_output_folder(path)
    if clip is not None:
        clip = clip.copy()   # the editor may change its clip while we render

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
        pose = rig.rest_pose()
        if camera is not None:
            apply_camera(plotter.camera, camera)
        else:
            scene.view(view, angle, points=swept_points(rig, clip, times))
        if clip is not None:
            clip.sample(times[0], out=pose)
        model0 = scene.update(pose)
        base_pos = np.array(plotter.camera.position)
        base_focal = np.array(plotter.camera.focal_point)
        root0 = model0[0, :3, 3].copy()
        up = scene.up
        camera = plotter.camera
        # pyvista's render() does nothing until a first show() or screenshot()
        plotter.screenshot(return_img=False)
        depth = 2
        reader = FrameReader(plotter, buffers=depth + 2)
        writer = _ThreadedWriter(_Writer(path, fps, quality, preset), depth, reader.image)
        for i, t in enumerate(times):
            if clip is not None:
                clip.sample(t, out=pose)
            model = scene.update(pose)
            shift = _horizontal(model[0, :3, 3] - root0, up) if follow_root else np.zeros(3)
            rel = base_pos - base_focal
            if orbit:
                rel = turn_about(rel, up, orbit * i / max(len(times), 1))
            # VTK's setters: pyvista's reset the clipping range (all actors' bounds) each
            camera.SetFocalPoint(*(base_focal + shift))
            camera.SetPosition(*(base_focal + shift + rel))
            plotter.renderer.ResetCameraClippingRange()
            plotter.render()
            writer.append(reader.read())
            if progress is not None and progress(i + 1, len(times)) is False:
                raise RecordingCancelled(f"recording cancelled after {i + 1} frames")
        writer.commit()
        writer = None
        return len(times)
    finally:
        if writer is not None:
            writer.abort()
        plotter.close()


class FrameReader:
    """Reads the rendered frame's pixels into a ring of preallocated buffers (no per-frame
    filter or array as ``plotter.screenshot`` makes).

    Parameters
    ----------
    plotter : pyvista.Plotter
        Rendered off-screen at least once (pyvista's ``render()`` does nothing before that).
    buffers : int
        How many frames may be in use at once (queued for the encoder): a buffer is written
        again only after ``buffers - 1`` further reads.
    """

    def __init__(self, plotter, buffers=4):
        import vtk

        self.plotter = plotter
        self.ren_win = plotter.render_window
        self.width, self.height = (int(s) for s in self.ren_win.GetSize())
        self._vtk = [vtk.vtkUnsignedCharArray() for _ in range(max(1, buffers))]
        for arr in self._vtk:
            arr.SetNumberOfComponents(3)
            arr.SetNumberOfTuples(self.width * self.height)
        self._next = 0

    def read(self):
        """The last rendered frame as read, for :meth:`image` (which may run in another
        thread); a view of a buffer that a later read reuses."""
        from vtk.util.numpy_support import vtk_to_numpy

        arr = self._vtk[self._next]
        self._next = (self._next + 1) % len(self._vtk)
        # the front buffer, which screenshot() reads
        self.ren_win.GetPixelData(0, 0, self.width - 1, self.height - 1, 1, arr, 0)
        return vtk_to_numpy(arr).reshape(self.height, self.width, 3)

    @staticmethod
    def image(raw):
        """The picture of a :meth:`read` frame, top row first (VTK's rows run bottom-up).

        Returns
        -------
        image : (H, W, 3) uint8
            A view of ``raw``.
        """
        return raw[::-1]


class _ThreadedWriter:
    """A :class:`_Writer` fed from a thread through a bounded queue, so that ``prepare`` and
    writing a frame into ffmpeg's pipe (and waiting for it when the encoder lags) overlap the
    rendering of the next one. An error in the thread is raised, once, by the next :meth:`append` or by
    :meth:`commit`."""

    _END = object()

    def __init__(self, writer, depth=2, prepare=None):
        self.writer = writer
        self.prepare = prepare or (lambda frame: frame)
        self.depth = depth
        self.error = None
        self._queue = queue.Queue(maxsize=depth)
        self._thread = threading.Thread(target=self._run, name="rigedit-encoder", daemon=True)
        self._thread.start()

    def _run(self):
        while True:
            frame = self._queue.get()
            if frame is self._END:
                return
            if self.error is None:
                try:
                    self.writer.append(self.prepare(frame))
                except BaseException as exc:   # kept for the recording thread to raise
                    self.error = exc

    def _raise(self):
        if self.error is not None:
            raise self.error

    def append(self, frame):
        """Queue ``frame`` (H, W, 3) uint8; blocks while ``depth`` frames wait."""
        self._raise()
        self._queue.put(frame)

    def _finish(self):
        if self._thread.is_alive():
            self._queue.put(self._END)
            self._thread.join()

    def commit(self):
        self._finish()
        self._raise()
        self.writer.commit()

    def abort(self):
        # the thread still drains what is queued (frames are dropped once an error is kept)
        self.error = self.error or RecordingCancelled("aborted")
        self._finish()
        self.writer.abort()


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


def _horizontal(offset, up):
    """The part of ``offset`` (3,) perpendicular to the unit ``up`` axis."""
    return offset - np.dot(offset, up) * up


def swept_points(rig, clip, times, samples=12, per_frame=3000):
    """Vertices the clip sweeps over the recorded times, with the root's horizontal motion
    taken out (the camera follows it), to frame the whole motion. A rig without a mesh is
    framed by its joints (and bone tails) instead.

    Returns
    -------
    points : (N, 3) float64
    """
    step = max(1, len(rig.vertices) // per_frame)
    if clip is None:
        return rig.vertices[::step] if len(rig.vertices) else rig.bounds()
    up = up_vector(rig.up)
    pose = rig.rest_pose()
    pts, root0 = [], None
    for t in np.linspace(times[0], times[-1], min(samples, len(times))):
        clip.sample(t, out=pose)
        model = rig.joint_matrices(pose)
        root = model[0, :3, 3]
        root0 = root if root0 is None else root0
        shown = rig.skin(pose)[::step] if len(rig.vertices) else joint_points(rig, model)
        pts.append(shown - _horizontal(root - root0, up))
    return np.concatenate(pts)


def camera_state(camera):
    """The parts of a VTK/pyvista camera that :func:`record_clip` copies, as plain data."""
    return {"position": tuple(camera.position), "focal_point": tuple(camera.focal_point),
            "up": tuple(camera.up), "view_angle": float(camera.view_angle),
            "parallel_projection": bool(camera.parallel_projection),
            "parallel_scale": float(camera.parallel_scale)}


def apply_camera(camera, state):
    """Set a pyvista camera from :func:`camera_state`'s dictionary."""
    camera.position, camera.focal_point = state["position"], state["focal_point"]
    camera.up = state["up"]
    if "view_angle" in state:
        camera.view_angle = state["view_angle"]
    if state.get("parallel_projection"):
        camera.parallel_projection = True
        camera.parallel_scale = state.get("parallel_scale", camera.parallel_scale)
