"""Clips: keyframe tracks per joint and channel, sampled into poses."""
from __future__ import annotations

import numpy as np

from ..model.pose import Pose
from .interpolate import MODES, ROTATION_MODES, VECTOR_MODES, sample_track

__all__ = ["CHANNELS", "Track", "Clip"]

#: Channel name -> value width.
CHANNELS = {"translation": 3, "rotation": 4, "scale": 3}
DEFAULT_MODE = {"translation": "linear", "rotation": "slerp", "scale": "linear"}


class Track:
    """Keys of one channel of one joint.

    Parameters
    ----------
    channel : {"translation", "rotation", "scale"}
    times : (K,) float
        Key times in seconds, strictly increasing after sorting (duplicates rejected).
    values : (K, C) float
        Local values: translations and scales (C = 3) or quaternions x, y, z, w (C = 4).
    interpolation : str
        ``step`` or ``linear`` for vectors; ``step``, ``nlerp`` or ``slerp`` for rotations
        (``linear`` on a rotation means ``nlerp``).

    Notes
    -----
    Keys are validated once here: sorted by time, quaternions normalised and each flipped to
    its predecessor's hemisphere so that every interpolation takes the shortest path without a
    per-frame test.
    """

    __slots__ = ("channel", "times", "values", "interpolation")

    def __init__(self, channel, times, values, interpolation=None):
        if channel not in CHANNELS:
            raise ValueError(f"expected a channel in {sorted(CHANNELS)}, got {channel!r}")
        self.channel = channel
        width = CHANNELS[channel]
        times = np.asarray(times, dtype=np.float64).reshape(-1)
        values = np.asarray(values, dtype=np.float64)
        if len(times) == 0:
            raise ValueError(f"{channel} track: expected at least one key, got none")
        if values.shape != (len(times), width):
            raise ValueError(f"{channel} track: expected values of shape {(len(times), width)}, "
                             f"got {values.shape}")
        if not (np.all(np.isfinite(times)) and np.all(np.isfinite(values))):
            raise ValueError(f"{channel} track: expected finite numbers, got NaN or inf")
        order = np.argsort(times, kind="stable")
        times, values = times[order], values[order]
        if np.any(np.diff(times) <= 0):
            dup = times[1:][np.diff(times) <= 0][0]
            raise ValueError(f"{channel} track: two keys at time {dup:g}")
        if channel == "rotation":
            norm = np.linalg.norm(values, axis=1, keepdims=True)
            if np.any(norm < 1e-12):
                raise ValueError("rotation track: expected unit quaternions, got a zero one")
            values = values / norm
            for i in range(1, len(values)):
                if np.dot(values[i - 1], values[i]) < 0:
                    values[i] = -values[i]
        mode = interpolation or DEFAULT_MODE[channel]
        allowed = ROTATION_MODES + ("linear",) if channel == "rotation" else VECTOR_MODES
        if mode not in allowed:
            raise ValueError(f"{channel} track: expected interpolation in {allowed}, got {mode!r}")
        self.times, self.values, self.interpolation = times, values, mode

    def __len__(self):
        return len(self.times)

    def sample(self, t):
        """(C,) value at time ``t`` (clamped to the first and last key)."""
        return sample_track(self.times, self.values, t, self.interpolation,
                            self.channel == "rotation")

    def with_key(self, t, value):
        """A new track with a key set at ``t`` (replacing one at the same time)."""
        keep = np.abs(self.times - t) > 1e-9
        return Track(self.channel, np.r_[self.times[keep], t],
                     np.vstack([self.values[keep], np.asarray(value, dtype=float)]),
                     self.interpolation)

    def copy(self):
        return Track(self.channel, self.times.copy(), self.values.copy(), self.interpolation)


class Clip:
    """An animation clip: tracks keyed by ``(joint name, channel)``.

    Parameters
    ----------
    name : str
    skeleton : Skeleton
        Joints without a track keep their rest value.
    tracks : dict[(str, str), Track]
    duration : float, optional
        Length in seconds; the last key time when omitted.
    loop : bool
        Sampling wraps time into ``[0, duration)`` when true, clamps otherwise.
    """

    def __init__(self, name, skeleton, tracks=None, duration=None, loop=True):
        self.name = str(name)
        self.skeleton = skeleton
        self.tracks = {}
        self.loop = bool(loop)
        for (joint, channel), track in (tracks or {}).items():
            self.set_track(joint, channel, track)
        last = max((tr.times[-1] for tr in self.tracks.values()), default=0.0)
        self.duration = float(last if duration is None else duration)
        if self.duration < 0 or not np.isfinite(self.duration):
            raise ValueError(f"clip {self.name!r}: expected a duration >= 0, got {duration}")
        self.revision = 0

    def set_track(self, joint, channel, track):
        """Add or replace a track; ``KeyError`` for a joint the skeleton lacks."""
        self.skeleton.joint_index(joint)
        if track.channel != channel:
            raise ValueError(f"track for {joint!r}: expected channel {channel!r}, "
                             f"got {track.channel!r}")
        self.tracks[(joint, channel)] = track
        self.revision = getattr(self, "revision", 0) + 1

    def key_times(self, joint=None):
        """Sorted unique key times of one joint, or of all joints."""
        ts = [tr.times for (j, _), tr in self.tracks.items() if joint is None or j == joint]
        return np.unique(np.concatenate(ts)) if ts else np.zeros(0)

    def local_time(self, t):
        """Clip time for a playback time: wrapped when looping, clamped otherwise."""
        if self.duration <= 0:
            return 0.0
        if self.loop:
            # t = duration shows the last key rather than the first again, so a clip that is
            # not a perfect loop still ends on its final pose.
            r = float(t % self.duration)
            return self.duration if r == 0.0 and t > 0 else r
        return float(min(max(t, 0.0), self.duration))

    def sample(self, t, out=None):
        """The pose at time ``t`` seconds.

        Parameters
        ----------
        t : float
        out : Pose, optional
            Pose to write into (reset to rest for joints without tracks).

        Returns
        -------
        pose : Pose
        """
        pose = Pose(self.skeleton) if out is None else out
        if out is not None:
            pose.reset()
        t = self.local_time(t)
        index = self.skeleton.index
        for (joint, channel), track in self.tracks.items():
            getattr(pose, channel)[index[joint]] = track.sample(t)
        return pose

    def copy(self, name=None):
        return Clip(name or self.name, self.skeleton,
                    {k: tr.copy() for k, tr in self.tracks.items()}, self.duration, self.loop)

    def __repr__(self):
        return (f"Clip({self.name!r}, duration={self.duration:g}s, {len(self.tracks)} tracks, "
                f"loop={self.loop})")
