"""Keyframes, clips and interpolation (pure numpy; no Qt or VTK)."""
from .clip import CHANNELS, Clip, Track
from .interpolate import MODES, lerp, nlerp, sample_track, slerp

__all__ = ["Clip", "Track", "CHANNELS", "MODES", "lerp", "nlerp", "slerp", "sample_track"]
