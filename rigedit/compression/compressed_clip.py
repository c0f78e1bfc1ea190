"""Compressed clips the editor and the recorder sample like a :class:`~rigedit.animation.clip.Clip`."""
from __future__ import annotations

import numpy as np

from ..animation.clip import Clip
from ..animation.track import Track
from ..model.pose import Pose
from .codec import ClipDecoder, kernels_loaded
from .cubic import key_tangents
from .frames import local_times, sample_local
from .layout import read_clip

__all__ = ["CompressedClip", "KeyedClip"]

_MODE = {"translation": "linear", "rotation": "nlerp", "scale": "linear"}


class _Sampled:
    """What both kinds of compressed clip share: playback time, poses, key times."""

    local_time = Clip.local_time
    morph_tracks = {}   # weight tracks are not compressed (a compressed clip has none)

    def sample_morphs(self, t):
        return {}

    def sample(self, t, out=None):
        """The pose at playback time ``t`` (wrapped or clamped as :meth:`Clip.sample`)."""
        pose = Pose(self.skeleton) if out is None else out
        pose.set_array(self.sample_many(np.array([float(t)]))[0])
        return pose

    def plain(self):
        """:meth:`to_clip`, made once and kept: what readers of a clip's keys (writers,
        listings, the timeline) see."""
        if getattr(self, "_plain", None) is None:
            self._plain = self.to_clip()
        return self._plain

    @property
    def tracks(self):
        """The stored keys as plain tracks, ``{(joint, channel): Track}`` (read only)."""
        return self.plain().tracks

    def key_times(self, joint=None):
        return self.plain().key_times(joint)

    def morph_key_times(self, target=None):
        return np.zeros(0)

    def copy(self, name=None):
        """A plain, editable :class:`Clip` of the stored keys."""
        return self.to_clip(name)


class CompressedClip(_Sampled):
    """A clip in rigedit's compressed form, decoded on the fly (:mod:`.codec`).

    Parameters
    ----------
    skeleton : Skeleton
    blob : bytes
        The clip as :func:`~rigedit.compression.layout.write_clip` writes it.

    Raises
    ------
    rigedit.compression.layout.LayoutError
        A malformed blob.
    """

    def __init__(self, skeleton, blob):
        self.skeleton = skeleton
        self.blob = bytes(blob)
        layout, stream, offsets = read_clip(self.blob, len(skeleton))
        self.layout = layout
        self.name, self.duration, self.loop = layout.name, layout.duration, layout.loop
        self.revision = 0
        self.decoder = ClipDecoder(layout, stream, offsets, Pose(skeleton).as_array())
        self._row = np.empty(len(skeleton) * 10)
        self._first = True
        if kernels_loaded():
            self.decoder.use_kernels()

    @property
    def nbytes(self):
        """Size of the compressed clip, bytes."""
        return len(self.blob)

    def use_kernels(self, on=True):
        """Decode with numba's compiled kernels (imported on the first call; the numpy
        decoder otherwise). Returns whether they are in use."""
        return self.decoder.use_kernels(on)

    def sample(self, t, out=None):
        """The pose at playback time ``t`` (wrapped or clamped as :meth:`Clip.sample`)."""
        pose = Pose(self.skeleton) if out is None else out
        if self._first:   # playback: worth the compiled decoder (imported once, ~1 s)
            self._first = False
            self.decoder.use_kernels()
        self.decoder.pose_arrays(self.local_time(t), self._row, pose.translation,
                                 pose.rotation, pose.scale)
        return pose

    def sample_many(self, times):
        """Local poses (N, J, 10) at playback times (N,), one decode for all of them."""
        return self.decoder.local_many(local_times(self.duration, self.loop, times))

    def to_clip(self, name=None):
        """A plain :class:`Clip` of the stored keys, dequantised exactly as decoded:
        ``linear`` translations and scales, ``nlerp`` rotations, ``cubic_spline`` with the
        Catmull-Rom velocities (:func:`~rigedit.compression.cubic.key_tangents`) for a track
        of cubic keys; a constant track is one key."""
        sk = self.skeleton
        tracks = {}
        for tr in self.layout.constant:
            tracks[(sk.names[tr.joint], tr.channel)] = Track(
                tr.channel, [0.0], [np.asarray(tr.value, dtype=np.float64)], _MODE[tr.channel])
        for i, tr in enumerate(self.layout.animated):
            times, values = self.decoder.keys(i)
            if tr.cubic:       # Catmull-Rom keys: the same cubic as a Hermite track
                values, tangents = key_tangents(times, values, tr.channel == "rotation")
                track = Track(tr.channel, times, values, "cubic_spline",
                              np.repeat(tangents[:, None], 2, axis=1))
            else:
                track = Track(tr.channel, times, values, _MODE[tr.channel])
            tracks[(sk.names[tr.joint], tr.channel)] = track
        return Clip(name or self.name, sk, tracks, self.duration, self.loop)

    def __repr__(self):
        return (f"CompressedClip({self.name!r}, duration={self.duration:g}s, "
                f"{len(self.layout.animated)} animated + {len(self.layout.constant)} constant "
                f"tracks, {self.nbytes} bytes)")


class KeyedClip(_Sampled):
    """A reduced clip for glTF (``target="gltf"``): plain tracks whose values are what a glTF
    file holds (float32 times and vectors, rotations on the int16 grid)."""

    def __init__(self, clip, nbytes):
        self.clip = clip
        self.skeleton, self.name = clip.skeleton, clip.name
        self.duration, self.loop = clip.duration, clip.loop
        self.revision = 0
        self.nbytes = int(nbytes)

    def sample_many(self, times):
        return sample_local(self.clip, times, self.skeleton)

    def to_clip(self, name=None):
        return self.clip.copy(name)

    def __repr__(self):
        return f"KeyedClip({self.name!r}, {len(self.clip.tracks)} tracks, {self.nbytes} bytes)"
