"""What the timeline uses of :mod:`rigedit.animation`: the playback clock, frame snapping and
the interpolation mode names, so the UI reaches animation through the editor.

:class:`PlaybackClock` turns elapsed wall time into clip time (speed, loop, pause, seek);
:func:`snap_to_frame` rounds a time to the frame grid; :data:`ROTATION_MODES` and
:data:`VECTOR_MODES` are the interpolations a rotation and a translation/scale track take
(:meth:`KeyEditor.set_interpolation <rigedit.editor.timeline_keys.KeyEditor.set_interpolation>`).
"""
from __future__ import annotations

from ..animation.interpolate import ROTATION_MODES, VECTOR_MODES
from ..animation.playback import PlaybackClock, snap_to_frame

__all__ = ["PlaybackClock", "snap_to_frame", "ROTATION_MODES", "VECTOR_MODES"]
