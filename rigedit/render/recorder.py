"""Off-screen recording of a clip to MP4 (H.264, yuv420p) or GIF.

The recorder builds its own off-screen plotter and :class:`RigScene`, so it shares no mutable
state with an interactive view; frame ``i`` shows the clip at exactly ``t = start + i / fps``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pyvista as pv

from ..errors import RigFileError
from .scene import RigScene

__all__ = ["record_clip", "frame_times", "VIDEO_SUFFIXES", "RecordingCancelled"]

VIDEO_SUFFIXES = (".mp4", ".gif")


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
    def __init__(self, path, fps, quality):
        import imageio.v2 as imageio

        self.path = Path(path)
        self.gif = self.path.suffix.lower() == ".gif"
        self.frames = []
        if not self.gif:
            self.writer = imageio.get_writer(
                str(self.path), format="FFMPEG", mode="I", fps=fps, codec="libx264",
                pixelformat="yuv420p", quality=quality, macro_block_size=2,
                output_params=["-preset", "veryfast"])

    def append(self, frame):
        if self.gif:
            self.frames.append(frame)
        else:
            self.writer.append_data(frame)

    def close(self, fps):
        if self.gif:
            import imageio.v3 as iio

            iio.imwrite(self.path, np.stack(self.frames), extension=".gif",
                        duration=1000.0 / fps, loop=0)
        else:
            self.writer.close()


def record_clip(rig, clip, path, fps=30, duration=None, size=(1280, 720), start=0.0,
                view="front", angle=0.0, camera=None, orbit=0.0, follow_root=True,
                show_skeleton=False, multi_samples=0, quality=7, progress=None):
    """Render ``clip`` on ``rig`` off-screen into a video file.

    Parameters
    ----------
    rig : Rig
    clip : Clip or None
        None records the rest pose.
    path : str or Path
        ``.mp4`` (H.264, yuv420p) or ``.gif``.
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
        ``{"position", "focal_point", "up", "view_angle"}`` to copy (the editor's current view);
        overrides ``view``/``angle``.
    orbit : float
        Degrees the camera turns about the vertical axis over the recording.
    follow_root : bool
        Move the camera with the root joint's horizontal motion (walks stay in frame).
    multi_samples : int
        Anti-aliasing samples (0 is several times faster in software OpenGL).
    quality : int
        imageio-ffmpeg quality 0-10 for MP4.
    progress : callable(done, total) -> bool, optional
        Called after each frame; returning False cancels (raises ``RecordingCancelled``).

    Returns
    -------
    frames : int
        Frames written.
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
    if not path.parent.exists():
        raise RigFileError(path, "the folder does not exist")

    plotter = pv.Plotter(off_screen=True, window_size=(width, height))
    writer = None
    try:
        plotter.enable_anti_aliasing("msaa", multi_samples=multi_samples) if multi_samples \
            else plotter.disable_anti_aliasing()
        plotter.set_background("#eef1f4", top="#c5ccd6")
        scene = RigScene(plotter, rig, show_skeleton=show_skeleton)
        pose = rig.rest_pose()
        if clip is not None:
            clip.sample(times[0], out=pose)
        model0 = scene.update(pose)
        if camera is not None:
            cam = plotter.camera
            cam.position, cam.focal_point = camera["position"], camera["focal_point"]
            cam.up = camera["up"]
            if "view_angle" in camera:
                cam.view_angle = camera["view_angle"]
        else:
            scene.view(view, angle)
        base_pos = np.array(plotter.camera.position)
        base_focal = np.array(plotter.camera.focal_point)
        root0 = model0[0, :3, 3].copy()
        writer = _Writer(path, fps, quality)
        for i, t in enumerate(times):
            if clip is not None:
                clip.sample(t, out=pose)
            model = scene.update(pose)
            shift = np.zeros(3)
            if follow_root:
                shift = model[0, :3, 3] - root0
                shift -= np.dot(shift, scene.up) * scene.up  # horizontal part only
            rel = base_pos - base_focal
            if orbit:
                a = np.radians(orbit * i / max(len(times), 1))
                up = scene.up
                rel = (rel * np.cos(a) + np.cross(up, rel) * np.sin(a)
                       + up * np.dot(up, rel) * (1 - np.cos(a)))
            plotter.camera.focal_point = base_focal + shift
            plotter.camera.position = base_focal + shift + rel
            plotter.reset_camera_clipping_range()
            plotter.render()
            writer.append(plotter.screenshot(return_img=True))
            if progress is not None and progress(i + 1, len(times)) is False:
                raise RecordingCancelled(f"recording cancelled after {i + 1} frames")
        writer.close(fps)
        writer = None
        return len(times)
    except BaseException:
        if writer is not None:
            try:
                writer.close(fps)
            except Exception:
                pass
            path.unlink(missing_ok=True)
        raise
    finally:
        plotter.close()
