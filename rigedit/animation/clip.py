"""Clips: keyframe tracks per joint and channel, sampled into poses."""
from __future__ import annotations

import numpy as np

from ..model.pose import Pose
from .clip_names import check_clip_name
from .interpolate import ROTATION_MODES, VECTOR_MODES, catmull_rom_tangents, sample_track

__all__ = ["CHANNELS", "Track", "Clip"]

#: Channel name -> value width.
CHANNELS = {"translation": 3, "rotation": 4, "scale": 3}
DEFAULT_MODE = {"translation": "linear", "rotation": "slerp", "scale": "linear"}
#: Two key times closer than this (seconds) are the same key.
KEY_TOLERANCE = 1e-6


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
        ``step``, ``linear`` or ``catmull_rom`` for vectors; ``step``, ``nlerp``, ``slerp``,
        ``hybrid`` or ``catmull_rom`` for rotations (``linear`` on a rotation is read as
        ``nlerp``); ``cubic_spline`` for all three. See :mod:`rigedit.animation.interpolate`.
    tangents : (K, 2, C) float, optional
        ``cubic_spline`` only: the in- and out-tangent of each key (units per second, glTF's
        CUBICSPLINE); the Catmull-Rom tangents when omitted.

    Notes
    -----
    Keys are validated once here: sorted by time, quaternions normalised and each flipped to
    its predecessor's hemisphere so that every interpolation takes the shortest path without a
    per-frame test. Tracks are treated as immutable: edits return new tracks, so an undo
    snapshot of a clip is a shallow copy of its track dictionary.
    """

    __slots__ = ("channel", "times", "values", "interpolation", "tangents")

    def __init__(self, channel, times, values, interpolation=None, tangents=None):
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
        mode = interpolation or DEFAULT_MODE[channel]
        if channel == "rotation" and mode == "linear":
            mode = "nlerp"
        allowed = ROTATION_MODES if channel == "rotation" else VECTOR_MODES
        if mode not in allowed:
            raise ValueError(f"{channel} track: expected interpolation in {allowed}, got {mode!r}")
        if channel == "rotation":
            norm = np.linalg.norm(values, axis=1, keepdims=True)
            if np.any(norm < 1e-12):
                raise ValueError("rotation track: expected unit quaternions, got a zero one")
            if mode == "cubic_spline" and tangents is not None:
                # the spline runs through the keys as given with their tangents (glTF
                # evaluates it on the raw quaternions, then normalises): flipping or scaling a
                # key would change the curve
                pass
            else:
                values = values / norm
                # each key to its predecessor's hemisphere: key i flips when an odd number of the
                # raw neighbour products up to i are negative (the same as a loop, without one)
                dots = np.sum(values[1:] * values[:-1], axis=1)
                flips = np.cumprod(np.where(dots < 0, -1.0, 1.0))
                values[1:] *= flips[:, None]
        self.times, self.values, self.interpolation = times, values, mode
        # baked once: per-frame sampling of a spline is then one cubic
        self.tangents = None
        if mode == "catmull_rom":
            self.tangents = catmull_rom_tangents(times, values)
        elif mode == "cubic_spline":
            if tangents is None:
                tangents = np.repeat(catmull_rom_tangents(times, values)[:, None], 2, axis=1)
            tangents = np.asarray(tangents, dtype=np.float64)
            if tangents.shape != (len(times), 2, width):
                raise ValueError(f"{channel} track: expected tangents of shape "
                                 f"{(len(times), 2, width)}, got {tangents.shape}")
            if not np.all(np.isfinite(tangents)):
                raise ValueError(f"{channel} track: expected finite tangents, got NaN or inf")
            self.tangents = tangents[order]

    def _spline_tangents(self, keep):
        """In/out tangents of the kept keys (a boolean mask or index array) for a rebuilt
        ``cubic_spline`` track; None for other modes."""
        return self.tangents[keep] if self.interpolation == "cubic_spline" else None

    def _with(self, times, values, tangents):
        """A new track of the same channel and mode; ``tangents`` rows that are NaN (new keys
        of a ``cubic_spline`` track) get the Catmull-Rom tangent there."""
        if tangents is not None and np.isnan(tangents).any():
            order = np.argsort(times, kind="stable")
            cr = np.empty_like(tangents)
            cr[order] = catmull_rom_tangents(np.asarray(times)[order],
                                             np.asarray(values)[order])[:, None]
            tangents = np.where(np.isnan(tangents), cr, tangents)
        return Track(self.channel, times, values, self.interpolation, tangents)

    def __len__(self):
        return len(self.times)

    def sample(self, t):
        """(C,) value at time ``t`` (clamped to the first and last key)."""
        return sample_track(self.times, self.values, t, self.interpolation,
                            self.channel == "rotation", self.tangents)

    def key_index(self, t, tol=KEY_TOLERANCE):
        """Index of the key within ``tol`` seconds of ``t``, or None."""
        i = int(np.argmin(np.abs(self.times - t)))
        return i if abs(self.times[i] - t) <= tol else None

    def with_key(self, t, value):
        """A new track with a key set at ``t`` (replacing one at the same time)."""
        keep = np.abs(self.times - t) > KEY_TOLERANCE
        tangents = self._spline_tangents(keep)
        if tangents is not None:
            tangents = np.concatenate([tangents, np.full((1,) + tangents.shape[1:], np.nan)])
        return self._with(np.r_[self.times[keep], t],
                          np.vstack([self.values[keep], np.asarray(value, dtype=float)]),
                          tangents)

    def without_keys(self, times, tol=KEY_TOLERANCE):
        """A new track without the keys at ``times``; None when no key would remain."""
        times = np.atleast_1d(np.asarray(times, dtype=float))
        keep = np.all(np.abs(self.times[:, None] - times[None, :]) > tol, axis=1)
        if not keep.any():
            return None
        return self._with(self.times[keep], self.values[keep], self._spline_tangents(keep))

    def with_moved_keys(self, mapping, tol=KEY_TOLERANCE):
        """A new track with keys moved: ``mapping`` is ``{old time: new time}``.

        A moved key replaces a key already at its new time (one that is not moving itself).
        """
        new_t, new_v = [], []
        moved = set()
        for old, new in mapping.items():
            i = self.key_index(old, tol)
            if i is not None:
                moved.add(i)
                new_t.append(float(new))
                new_v.append(self.values[i])
        if not moved:
            return self
        rest = [i for i in range(len(self.times)) if i not in moved
                and np.all(np.abs(self.times[i] - np.asarray(new_t)) > tol)]
        times = np.r_[self.times[rest], new_t]
        values = np.vstack([self.values[rest].reshape(-1, self.values.shape[1]), new_v])
        tangents = None
        if self.interpolation == "cubic_spline":
            src = [self.key_index(old, tol) for old in mapping]
            tangents = np.concatenate([self.tangents[rest],
                                       self.tangents[[i for i in src if i is not None]]])
        return self._with(times, values, tangents)

    def with_interpolation(self, mode):
        """The same keys with another interpolation mode."""
        return Track(self.channel, self.times, self.values, mode)

    def copy(self):
        return Track(self.channel, self.times.copy(), self.values.copy(), self.interpolation,
                     self._spline_tangents(slice(None)))


class Clip:
    """An animation clip: tracks keyed by ``(joint name, channel)``.

    Parameters
    ----------
    name : str
        Checked by :func:`~rigedit.animation.clip_names.check_clip_name` (``ValueError``).
    skeleton : Skeleton
        Joints without a track keep their rest value.
    tracks : dict[(str, str), Track]
    duration : float, optional
        Length in seconds; the last key time when omitted.
    loop : bool
        Sampling wraps time into ``[0, duration)`` when true, clamps otherwise.
    """

    def __init__(self, name, skeleton, tracks=None, duration=None, loop=True):
        self.name = check_clip_name(name)
        self.skeleton = skeleton
        self.tracks = {}
        self.loop = bool(loop)
        self.revision = 0
        for (joint, channel), track in (tracks or {}).items():
            self.set_track(joint, channel, track)
        last = max((tr.times[-1] for tr in self.tracks.values()), default=0.0)
        self.duration = float(last if duration is None else duration)
        if self.duration < 0 or not np.isfinite(self.duration):
            raise ValueError(f"clip {self.name!r}: expected a duration >= 0, got {duration}")

    def set_track(self, joint, channel, track):
        """Add or replace a track; ``KeyError`` for a joint the skeleton lacks."""
        self.skeleton.joint_index(joint)
        if track.channel != channel:
            raise ValueError(f"track for {joint!r}: expected channel {channel!r}, "
                             f"got {track.channel!r}")
        self.tracks[(joint, channel)] = track
        self._touch()

    def remove_track(self, joint, channel):
        if self.tracks.pop((joint, channel), None) is not None:
            self._touch()

    # ------------------------------------------------------------------ editing
    # Each edit replaces whole Track objects (never mutates one), so ``state()`` is cheap and
    # an undo command stores two states.
    def _touch(self):
        self.revision += 1

    def state(self):
        """A snapshot for undo: restore it with :meth:`restore`."""
        return (dict(self.tracks), self.duration, self.loop, self.name)

    def restore(self, state):
        tracks, self.duration, self.loop, self.name = state
        self.tracks = dict(tracks)
        self._touch()

    def set_key(self, joint, channel, t, value):
        """Key one channel of one joint at ``t`` (creating the track)."""
        track = self.tracks.get((joint, channel))
        if track is None:
            self.set_track(joint, channel, Track(channel, [t], [value]))
        else:
            self.set_track(joint, channel, track.with_key(t, value))

    def key_pose(self, pose, t, joints=None):
        """Key ``joints`` (names; all when None) of ``pose`` at time ``t``.

        Rotation is always keyed; translation and scale only where the joint already has that
        track or the pose moves it away from rest, so keying a rotation-only rig does not add
        tracks that hold the rest value.

        Returns
        -------
        count : int
            Channels keyed.
        """
        sk = self.skeleton
        names = sk.names if joints is None else list(joints)
        count = 0
        for name in names:
            j = sk.joint_index(name)
            for channel in ("translation", "rotation", "scale"):
                value = getattr(pose, channel)[j]
                rest = getattr(sk, f"rest_{channel}")[j]
                if (channel == "rotation" or (name, channel) in self.tracks
                        or not np.allclose(value, rest, atol=1e-9)):
                    self.set_key(name, channel, t, value)
                    count += 1
        return count

    def _selected(self, joints):
        wanted = None if joints is None else set(joints)
        return [k for k in self.tracks if wanted is None or k[0] in wanted]

    def delete_keys(self, times, joints=None):
        """Delete the keys at ``times`` (seconds) of ``joints`` (all when None); a track that
        loses its last key is removed. Returns the number of keys deleted."""
        times = np.atleast_1d(np.asarray(times, dtype=float))
        deleted = 0
        for key in self._selected(joints):
            track = self.tracks[key]
            new = track.without_keys(times)
            n = len(track) - (0 if new is None else len(new))
            if n:
                deleted += n
                if new is None:
                    del self.tracks[key]
                else:
                    self.tracks[key] = new
        if deleted:
            self._touch()
        return deleted

    def move_keys(self, mapping, joints=None):
        """Move keys in time: ``mapping`` is ``{old time: new time}`` (negative times are
        rejected). Returns the number of tracks changed."""
        for new in mapping.values():
            if not np.isfinite(new) or new < 0:
                raise ValueError(f"clip {self.name!r}: expected key times >= 0, got {new}")
        changed = 0
        for key in self._selected(joints):
            track = self.tracks[key]
            new = track.with_moved_keys(mapping)
            if new is not track:
                self.tracks[key] = new
                changed += 1
        if changed:
            self._touch()
        return changed

    def copy_keys(self, t, joints=None):
        """The values of ``joints``' tracks at time ``t``: ``{(joint, channel): value}``, for
        :meth:`paste_keys` (a time between keys copies the interpolated value)."""
        t = self.local_time(t)
        return {k: self.tracks[k].sample(t) for k in self._selected(joints)}

    def paste_keys(self, data, t):
        """Key every ``(joint, channel): value`` of ``data`` at ``t``."""
        for (joint, channel), value in data.items():
            self.set_key(joint, channel, t, value)
        return len(data)

    def set_interpolation(self, mode, joint=None, channel=None):
        """Set the interpolation of one track, or of every track matching ``joint`` and/or
        ``channel`` (None matches all). ``ValueError`` when a track does not support ``mode``
        (nothing is changed then). Returns the number of tracks set."""
        keys = [k for k in self.tracks if (joint is None or k[0] == joint)
                and (channel is None or k[1] == channel)]
        new = {k: self.tracks[k].with_interpolation(mode) for k in keys}
        self.tracks.update(new)
        if new:
            self._touch()
        return len(new)

    def set_duration(self, duration):
        duration = float(duration)
        if not np.isfinite(duration) or duration <= 0:
            raise ValueError(f"clip {self.name!r}: expected a duration > 0, got {duration}")
        self.duration = duration
        self._touch()

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
