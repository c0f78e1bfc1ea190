"""Writing recorded frames: a video file written atomically, fed from a thread.

:class:`VideoWriter` streams frames to ffmpeg (MP4, H.264) or collects them for a GIF, into
a temporary file beside the target that :meth:`~VideoWriter.commit` renames over it;
:class:`ThreadedWriter` feeds a writer from its own thread through a bounded queue, so that
writing a frame overlaps the rendering of the next one; :class:`FrameReader` reads a
rendered frame's pixels into a ring of reused buffers. The loop that uses them is
:func:`rigedit.render.recorder.record_clip`.
"""
from __future__ import annotations

import contextlib
import os
import queue
import threading
from pathlib import Path

from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkUnsignedCharArray

from ..io.atomic import remove_stale_temps, temp_beside, write_error
from ..progress import Cancelled

__all__ = ["VideoWriter", "ThreadedWriter", "FrameReader", "RecordingCancelled"]


class RecordingCancelled(Cancelled):
    """The progress callback asked to stop; the partial file was removed. A
    :class:`rigedit.progress.Cancelled`, the one cancel of every long job."""


class VideoWriter:
    """Streams frames to ffmpeg (MP4) or collects palette frames (GIF) into a temporary file;
    :meth:`commit` renames it over the target."""

    def __init__(self, path, fps, quality, preset="veryfast"):
        import imageio.v2 as imageio

        self.path = Path(path)
        self.fps = fps
        self.gif = self.path.suffix.lower() == ".gif"
        # a render killed with SIGKILL could not remove its temporary video: the next one to
        # the same file does (the names carry the pid; those of live processes stay)
        remove_stale_temps(self.path, suffix=self.path.suffix)
        fd, tmp = temp_beside(self.path, suffix=self.path.suffix, tagged=True)
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
                    # frame threads cost 0.9 ms more CPU a frame for the same file)
                    output_params=["-preset", preset, "-threads", "1"] + (
                        # veryfast with 5 frames of rate-control lookahead instead of 10
                        # (the close waits for 40 ms less encoding) and sub-pixel motion
                        # refinement 1 instead of 2: x264's CPU a 1280x720 frame 10.2 ms
                        # instead of 12.2, for a 9% bigger file at 0.2 dB lower PSNR
                        # (42.3 dB; the walk at crf 15, README Speed > Recording). The
                        # render shares the cores with the encoder: its CPU sets the rate
                        ["-x264-params", "rc-lookahead=5:subme=1"]
                        if preset == "veryfast" else []),
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
            with contextlib.suppress(OSError):
                self.tmp.unlink()
            raise write_error(exc, self.path) from None

    def abort(self):
        with contextlib.suppress(Exception):
            if not self.gif:
                self.writer.close()
        self.frames = []
        with contextlib.suppress(OSError):
            self.tmp.unlink()


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
        self.plotter = plotter
        self.ren_win = plotter.render_window
        self.width, self.height = (int(s) for s in self.ren_win.GetSize())
        self._vtk = [vtkUnsignedCharArray() for _ in range(max(1, buffers))]
        for arr in self._vtk:
            arr.SetNumberOfComponents(3)
            arr.SetNumberOfTuples(self.width * self.height)
        self._next = 0

    def read(self):
        """The last rendered frame as read, for :meth:`image` (which may run in another
        thread); a view of a buffer that a later read reuses."""
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


class ThreadedWriter:
    """A :class:`VideoWriter` fed from a thread through a bounded queue, so that ``prepare``
    and writing a frame into ffmpeg's pipe (and waiting for it when the encoder lags) overlap
    the rendering of the next one. An error in the thread is raised, once, by the next
    :meth:`append` or by :meth:`commit`."""

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
