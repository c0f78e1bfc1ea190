"""Clips: keyframe tracks per joint and channel (:mod:`.track`) and weight tracks per morph
target (:mod:`.morph_track`), sampled into poses and weights."""
from __future__ import annotations

import numpy as np

from ..model.pose import Pose
from .clip_names import check_clip_name
from .curve_pack import BezierTracks
from .morph_track import WeightTrack
from .track import CHANNELS, DEFAULT_MODE, KEY_TOLERANCE, Track

__all__ = ["CHANNELS", "DEFAULT_MODE", "KEY_TOLERANCE", "Track", "Clip", "WeightTrack"]


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
    morph_tracks : dict[str, WeightTrack], optional
        Morph target name -> its weight track (:attr:`morph_tracks`, sampled by
        :meth:`sample_morphs`). Names are not checked against a mesh: a clip belongs to a
        skeleton, and a rig ignores weights of targets it does not have.
    """

    def __init__(self, name, skeleton, tracks=None, duration=None, loop=True,
                 morph_tracks=None):
        self.name = check_clip_name(name)
        self.skeleton = skeleton
        self.tracks = {}
        self.morph_tracks = {}
        self.loop = bool(loop)
        self.revision = 0
        self._bezier = None   # (revision, skeleton, BezierTracks): tracks split for sample
        for (joint, channel), track in (tracks or {}).items():
            self.set_track(joint, channel, track)
        for target, track in (morph_tracks or {}).items():
            self.set_morph_track(target, track)
        last = max((tr.times[-1] for tr in self._all_tracks()), default=0.0)
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

    def set_morph_track(self, target, track):
        """Add or replace the weight track of morph target ``target``."""
        if not isinstance(track, WeightTrack):
            raise TypeError(f"morph track {target!r}: expected a WeightTrack, got "
                            f"{type(track).__name__}")
        self.morph_tracks[str(target)] = track
        self._touch()

    def remove_morph_track(self, target):
        if self.morph_tracks.pop(target, None) is not None:
            self._touch()

    def set_morph_key(self, target, t, weight):
        """Key morph target ``target``'s weight at ``t`` (creating its track)."""
        track = self.morph_tracks.get(target)
        self.set_morph_track(target, WeightTrack([t], [weight]) if track is None
                             else track.with_key(t, weight))

    def sample_morphs(self, t):
        """``{target name: weight}`` at playback time ``t`` (wrapped or clamped as
        :meth:`sample`); empty when the clip has no weight tracks."""
        if not self.morph_tracks:
            return {}
        t = self.local_time(t)
        return {name: tr.sample(t) for name, tr in self.morph_tracks.items()}

    def _all_tracks(self):
        """The joint tracks, then the weight tracks."""
        return list(self.tracks.values()) + list(self.morph_tracks.values())

    # ------------------------------------------------------------------ editing
    # Each edit replaces whole Track objects (never mutates one), so ``state()`` is cheap and
    # an undo command stores two states.
    def _touch(self):
        self.revision += 1

    def state(self):
        """A snapshot for undo: restore it with :meth:`restore`."""
        return (dict(self.tracks), self.duration, self.loop, self.name, dict(self.morph_tracks))

    def restore(self, state):
        tracks, self.duration, self.loop, self.name = state[:4]
        self.tracks = dict(tracks)
        # a snapshot of before the weight tracks (4 items) has none
        self.morph_tracks = dict(state[4]) if len(state) > 4 else {}
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

    def _selected_morphs(self, joints):
        """The weight tracks an edit of ``joints`` touches: all of them for all joints (None),
        none for a joint selection."""
        return list(self.morph_tracks) if joints is None else []

    def delete_keys(self, times, joints=None):
        """Delete the keys at ``times`` (seconds) of ``joints`` (all when None, weight tracks
        included); a track that loses its last key is removed. Returns the number of keys
        deleted."""
        times = np.atleast_1d(np.asarray(times, dtype=float))
        deleted = 0
        for tracks, keys in ((self.tracks, self._selected(joints)),
                             (self.morph_tracks, self._selected_morphs(joints))):
            for key in keys:
                track = tracks[key]
                new = track.without_keys(times)
                n = len(track) - (0 if new is None else len(new))
                if n:
                    deleted += n
                    if new is None:
                        del tracks[key]
                    else:
                        tracks[key] = new
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
        for tracks, keys in ((self.tracks, self._selected(joints)),
                             (self.morph_tracks, self._selected_morphs(joints))):
            for key in keys:
                track = tracks[key]
                new = track.with_moved_keys(mapping)
                if new is not track:
                    tracks[key] = new
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
        """Sorted unique key times of one joint, or of all joints (and the weight tracks)."""
        ts = [tr.times for (j, _), tr in self.tracks.items() if joint is None or j == joint]
        if joint is None:
            ts += [tr.times for tr in self.morph_tracks.values()]
        return np.unique(np.concatenate(ts)) if ts else np.zeros(0)

    def morph_key_times(self, target=None):
        """Sorted unique key times of one weight track, or of all of them."""
        ts = [tr.times for name, tr in self.morph_tracks.items()
              if target is None or name == target]
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
        split = self.bezier_tracks()
        for row, channel, track in split.plain:
            getattr(pose, channel)[row] = track.sample(t)
        split.write(pose, t)
        return pose

    def bezier_tracks(self):
        """The clip's tracks split for sampling: the bezier ones packed to be sampled in one
        call (:class:`~rigedit.animation.curve_pack.BezierTracks`), rebuilt when
        :attr:`revision` changed."""
        got = self._bezier
        if got is None or got[0] != self.revision or got[1] is not self.skeleton:
            got = self._bezier = (self.revision, self.skeleton,
                                  BezierTracks(self.tracks, self.skeleton.index))
        return got[2]

    def copy(self, name=None):
        return Clip(name or self.name, self.skeleton,
                    {k: tr.copy() for k, tr in self.tracks.items()}, self.duration, self.loop,
                    {k: tr.copy() for k, tr in self.morph_tracks.items()})

    def __repr__(self):
        morphs = f", {len(self.morph_tracks)} weight tracks" if self.morph_tracks else ""
        return (f"Clip({self.name!r}, duration={self.duration:g}s, {len(self.tracks)} tracks"
                f"{morphs}, loop={self.loop})")
