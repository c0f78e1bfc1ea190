"""The frames a clip is checked on, and clips sampled at many times at once.

"Every frame" of a clip (the times the guarantee holds on) is the union of

- the clip's own key times (a mocap clip: its frames), and
- a sampling at the clip's frame rate over ``[0, duration]``. A clip whose median key spacing
  is under 1/20 s is keyed at every frame: its rate is 1 / that spacing (rounded to a whole
  number of frames per second when within 1%). A sparser clip's rate is the first of 30, 24,
  25, 60, 50 and 120 Hz on whose frames all its keys fall (within 1% of a frame), else 30 Hz;
  30 Hz too for a clip with fewer than two distinct key times.

A clip keyed at 120 Hz is checked at its 120 Hz frames; a clip keyed sparsely at 30 fps frame
numbers is checked at every 30 Hz frame between its keys, not only at the keys.
"""
from __future__ import annotations

import numpy as np

from ..animation.clip import Clip
from ..animation.track import KEY_TOLERANCE
from ..model.pose import Pose

__all__ = ["FALLBACK_RATE", "COLUMNS", "frame_rate", "frame_times", "local_times", "sample_local",
           "sample_track_many"]

#: Frames per second of a clip whose keys show none (fewer than two distinct key times, or
#: sparse keys on no rate of :data:`SPARSE_RATES`).
FALLBACK_RATE = 30.0
#: Keys closer than 1 / DENSE_RATE seconds (median) are a clip keyed at every frame.
DENSE_RATE = 20.0
#: The frame rates a sparsely keyed clip may be authored at, in the order they are tried.
SPARSE_RATES = (30, 24, 25, 60, 50, 120)
#: At most this many frames are checked per clip (a bound on memory: 10 floats per joint per
#: frame); a longer clip at its rate is an error rather than an allocation the size it claims.
MAX_FRAMES = 2_000_000
#: Two times under a microsecond apart are one frame unless the pose changes between them
#: by more than JUMP times what its speed over the frame before or after gives, plus
#: SAME_POSE (metres, quaternion components, scale): a jump.
JUMP = 10.0
SAME_POSE = 1e-6
#: Columns of a channel in a (..., 10) local pose row.
COLUMNS = {"translation": slice(0, 3), "rotation": slice(3, 7), "scale": slice(7, 10)}


def frame_rate(clip):
    """Frames per second the clip's keys show (see the module notes), float."""
    times = clip.key_times()
    steps = np.diff(times)
    steps = steps[steps > KEY_TOLERANCE]
    if len(steps) == 0:
        return FALLBACK_RATE
    rate = 1.0 / float(np.median(steps))
    if rate >= DENSE_RATE:       # keyed every frame (mocap, a baked clip): its own rate
        whole = round(rate)
        return float(whole) if abs(rate - whole) <= 0.01 * whole else rate
    for rate in SPARSE_RATES:    # keyed on some frames: the first rate they all fall on
        frames = times * rate
        if np.all(np.abs(frames - np.round(frames)) <= 0.01):
            return float(rate)
    return FALLBACK_RATE


def frame_times(clip, rate=None):
    """Sorted times (F,) float64 the clip is checked on: its key times and its frames.

    Parameters
    ----------
    clip : Clip
    rate : float, optional
        Frames per second; :func:`frame_rate` when omitted.
    """
    rate = frame_rate(clip) if rate is None else float(rate)
    duration = max(float(clip.duration), 0.0)
    count = int(np.floor(duration * rate + 1e-6)) + 1
    if count > MAX_FRAMES:
        raise ValueError(f"clip {clip.name!r}: {count} frames at {rate:g} Hz, expected at most "
                         f"{MAX_FRAMES}")
    grid = np.arange(count) / rate
    keys = clip.key_times()
    keys = keys[(keys >= 0) & (keys <= duration + KEY_TOLERANCE)]
    if len(keys):
        # a key within 1% of a frame period of a frame (float32 times in files) is that frame
        near = np.clip(np.searchsorted(keys, grid), 1, len(keys) - 1) if len(keys) > 1 else 0
        gap = np.minimum(np.abs(keys[near] - grid), np.abs(keys[near - 1] - grid)) \
            if len(keys) > 1 else np.abs(keys[0] - grid)
        grid = grid[gap > 0.01 / rate]
    times = np.union1d(grid, keys)
    close = np.flatnonzero(np.diff(times) <= KEY_TOLERANCE) + 1
    if len(close):
        # a time within a microsecond of the one before is the same frame where the clip
        # moves between them as it moves around them (tracks keyed a few ns apart: an FBX's
        # tick conversion), and a frame of its own where it jumps (a jump baked as two keys
        # 1e-7 s apart): a change over the gap beyond JUMP times what the pose's speed over
        # the frame period before or after gives it
        a, b = times[close - 1], times[close]
        step = 1.0 / rate
        p = sample_local(clip, np.concatenate([a - step, a, b, b + step]))
        before, pa, pb, after = np.split(p.reshape(len(p), -1), 4)
        change = np.abs(pb - pa)
        speed = np.maximum(np.abs(pa - before), np.abs(after - pb))
        expected = speed * ((b - a) / step)[:, None]
        jump = np.any(change > JUMP * expected + SAME_POSE, axis=1)
        times = np.delete(times, close[~jump])
    return times


def local_times(duration, loop, times):
    """:meth:`Clip.local_time` of many playback times (N,) at once."""
    times = np.asarray(times, dtype=np.float64)
    if duration <= 0:
        return np.zeros_like(times)
    if loop:
        r = np.mod(times, duration)
        return np.where((r == 0.0) & (times > 0), duration, r)
    return np.clip(times, 0.0, duration)


def _rotation_pair(a, b, u, mode):
    """Rotations between unit quaternions ``a`` and ``b`` (N, 4) at fractions ``u`` (N,)."""
    dot = np.sum(a * b, axis=1)
    b = np.where(dot[:, None] < 0, -b, b)
    dot = np.abs(dot)
    q = a + (b - a) * u[:, None]
    if mode in ("slerp", "hybrid"):
        theta = np.arccos(np.clip(dot, -1.0, 1.0))
        use = dot <= 1.0 - 1e-10
        if mode == "hybrid":
            from ..animation.interpolate import HYBRID_THRESHOLD
            use &= dot < np.cos(HYBRID_THRESHOLD / 2)
        if use.any():
            th, uu = theta[use], u[use]
            s = np.sin(th)
            q[use] = ((np.sin((1 - uu) * th) / s)[:, None] * a[use]
                      + (np.sin(uu * th) / s)[:, None] * b[use])
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def sample_track_many(track, times):
    """A track's values at many times, (N, C) float64, as ``track.sample`` gives them one by
    one (vectorised for ``step``, ``linear``, ``nlerp``, ``slerp`` and ``hybrid``; the spline
    modes sample key by key)."""
    times = np.asarray(times, dtype=np.float64)
    kt, kv = track.times, track.values
    if len(kt) == 1:
        value = track.sample(float(kt[0]))
        return np.repeat(value[None], len(times), axis=0)
    mode = track.interpolation
    if mode in ("catmull_rom", "cubic_spline", "bezier"):   # bezier: curves between keys
        return track.sample_many(times)   # one vectorised call (bezier: its curves)
    i = np.clip(np.searchsorted(kt, times, side="right") - 1, 0, len(kt) - 2)
    a, b = kv[i], kv[i + 1]
    if mode == "step":
        return np.where((times >= kt[i + 1])[:, None], b, a)
    u = np.clip((times - kt[i]) / (kt[i + 1] - kt[i]), 0.0, 1.0)
    if track.channel == "rotation":
        return _rotation_pair(a, b, u, mode)
    return a + (b - a) * u[:, None]


def sample_local(clip, times, skeleton=None):
    """Local poses of a clip at many times, (F, J, 10) float64: translation, rotation (x, y,
    z, w), scale per joint, as :meth:`Pose.as_array` lays them out.

    ``clip`` is a :class:`~rigedit.animation.clip.Clip`, an object with ``sample_many(times)``
    (a compressed clip) or any object with ``sample(t, out)`` (sampled time by time).
    Times are playback times (wrapped or clamped by the clip).
    """
    times = np.asarray(times, dtype=np.float64).reshape(-1)
    if hasattr(clip, "sample_many"):
        return clip.sample_many(times)
    skeleton = clip.skeleton if skeleton is None else skeleton
    pose = Pose(skeleton)
    if isinstance(clip, Clip):
        out = np.repeat(pose.as_array()[None], len(times), axis=0)
        local = local_times(clip.duration, clip.loop, times)
        for (joint, channel), track in clip.tracks.items():
            out[:, skeleton.index[joint], COLUMNS[channel]] = sample_track_many(track, local)
        return out
    return np.stack([clip.sample(float(t), out=pose).as_array() for t in times])
