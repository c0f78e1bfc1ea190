"""The playback clock: wall time -> clip time, with speed, loop and skip-ahead (pure).

The clock never counts frames: clip time is ``anchor + (now - wall_anchor) * speed``, so a
slow frame makes the next one jump ahead instead of slowing the clip down. The caller passes
``now`` (``time.perf_counter()`` in the editor), which keeps the clock testable without
sleeping.
"""
from __future__ import annotations

__all__ = ["PlaybackClock", "snap_to_frame"]


def snap_to_frame(t, fps):
    """``t`` rounded to the nearest frame of a ``fps`` grid."""
    return round(t * fps) / fps


class PlaybackClock:
    """Maps wall-clock time to clip time.

    Parameters
    ----------
    duration : float
        Clip length in seconds (> 0 for time to move).
    speed : float
        Clip seconds per wall second (negative plays backwards).
    loop : bool
        Wrap into ``[0, duration)`` when true; stop at the end (or start) otherwise.

    Attributes
    ----------
    playing : bool
    """

    def __init__(self, duration=1.0, speed=1.0, loop=True):
        self.duration = float(duration)
        self.speed = float(speed)
        self.loop = bool(loop)
        self.playing = False
        self._anchor = 0.0        # clip time at _wall
        self._wall = 0.0

    # ------------------------------------------------------------------ queries
    def time(self, now):
        """Clip time at wall time ``now``. A non-looping clock that reaches an end stops
        there (``playing`` turns false)."""
        if not self.playing:
            return self._anchor
        t = self._anchor + (now - self._wall) * self.speed
        d = self.duration
        if d <= 0:
            return 0.0
        if self.loop:
            return t % d   # Python's modulo is in [0, d) for negative t too
        if t >= d or t <= 0 and self.speed < 0:
            self._anchor = min(max(t, 0.0), d)
            self.playing = False
            return self._anchor
        return max(t, 0.0)

    # ------------------------------------------------------------------ control
    def play(self, now):
        """Start from the current time (from the start when a one-shot clock sits at its
        end)."""
        if self.playing:
            return
        if not self.loop and self.duration > 0:
            if self.speed >= 0 and self._anchor >= self.duration:
                self._anchor = 0.0
            elif self.speed < 0 and self._anchor <= 0:
                self._anchor = self.duration
        self._wall = now
        self.playing = True

    def pause(self, now):
        """Freeze at the current time."""
        if self.playing:
            self._anchor = self.time(now)
            self.playing = False

    def stop(self):
        """Pause and return to time 0."""
        self.playing = False
        self._anchor = 0.0

    def seek(self, t, now):
        """Jump to clip time ``t`` (playing continues from there)."""
        self._anchor = float(t)
        self._wall = now

    def set_speed(self, speed, now):
        """Change speed without a jump in clip time."""
        self._anchor = self.time(now)
        self._wall = now
        self.speed = float(speed)

    def set_duration(self, duration, now):
        self._anchor = self.time(now)
        self._wall = now
        self.duration = float(duration)

    def set_loop(self, loop, now):
        self._anchor = self.time(now)
        self._wall = now
        self.loop = bool(loop)
