"""Keyframes, clips, interpolation and the playback clock (pure numpy; no Qt or VTK)."""
from .clip import CHANNELS, Clip, Track
from .morph_track import WeightTrack
from .interpolate import MODES, ROTATION_MODES, VECTOR_MODES, lerp, nlerp, sample_track, slerp
from .playback import PlaybackClock

__all__ = ["Clip", "Track", "CHANNELS", "MODES", "VECTOR_MODES", "ROTATION_MODES", "lerp",
           "nlerp", "slerp", "sample_track", "PlaybackClock", "WeightTrack"]
