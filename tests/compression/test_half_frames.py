"""Halfway between frames: a fast swing keyed at 24 fps holds the bound there too (NLERP over a
wide span strays most between frames), the compiled reducer keeps the numpy one's keys, and a
source that curves between its frames (spline keys) compresses within the bound at its
frames without the check giving up on what no key mends."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import rigedit
from rigedit.animation import Clip, Track
from rigedit.compression import compress_clips
from rigedit.compression.frames import frame_times
from rigedit.compression.kernels import load
from rigedit.compression.reduce import reduce_keys

from compression_characters import chain, smooth_rotations
from test_pipeline import _independent_error

BOUND = 5e-4


def _fast_swing(sk, frames=18, rate=24.0):
    """Every joint turning ~35 degrees a frame about a wandering axis (a jump's arm swing)."""
    t = np.arange(frames) / rate
    tracks = {}
    for j, name in enumerate(sk.names):
        rng = np.random.default_rng(j)
        angle = 0.6 * np.arange(frames) + rng.uniform(0, 1)
        axis = np.column_stack([np.cos(0.3 * t + j), np.sin(0.3 * t + j), 0.4 + 0 * t])
        axis /= np.linalg.norm(axis, axis=1, keepdims=True)
        tracks[(name, "rotation")] = Track("rotation", t, Rotation.from_rotvec(
            axis * angle[:, None]).as_quat(), "slerp")
    return Clip("swing", sk, tracks)


@pytest.mark.parametrize("target", ["rigedit", "gltf"])
def test_a_fast_swing_holds_halfway_between_frames(target):
    sk = chain(5, 0.15)
    clip = _fast_swing(sk)
    result = compress_clips(sk, {"swing": clip}, max_error=BOUND, target=target)
    packed = result.clips["swing"]
    times = frame_times(clip)
    halves = 0.5 * (times[1:] + times[:-1])
    assert _independent_error(sk, clip, packed, times).max() <= BOUND * (1 + 1e-9)
    assert _independent_error(sk, clip, packed, halves).max() <= BOUND * (1 + 1e-6)


def test_frames_alone_let_a_fast_swing_stray_between_them():
    # the reducer without the half-frames: every frame within the tolerance, halfway not
    times = np.arange(18) / 24.0
    fine = Rotation.from_rotvec(np.outer(0.3 * np.arange(35), [0, 0.6, 0.8])).as_quat()[None]
    ref, mid = fine[:, ::2], fine[:, 1::2]
    tol = np.array([1e-3])
    plain = reduce_keys(times, ref, ref, tol, True, compiled=False)
    held = reduce_keys(times, ref, ref, tol, True, compiled=False, mid_reference=mid)
    assert held.sum() > plain.sum()
    for keep, strays in ((plain, True), (held, False)):
        keys = np.flatnonzero(keep[0])
        k = np.clip(np.searchsorted(keys, np.arange(17), side="right") - 1, 0, len(keys) - 2)
        a, b = keys[k], keys[k + 1]
        u = (np.arange(17) + 0.5 - a) / (b - a)
        q = ref[0, a] + (ref[0, b] - ref[0, a]) * u[:, None]
        q /= np.linalg.norm(q, axis=1, keepdims=True)
        err = np.minimum(np.linalg.norm(q - mid[0], axis=1), np.linalg.norm(q + mid[0], axis=1))
        assert (err.max() > tol[0]) == strays


def test_compiled_reduction_with_half_frames_keeps_the_same_keys():
    if load("reduce_kernels") is None:
        pytest.skip("numba is not installed or RIGEDIT_NO_NUMBA is set")
    times = np.arange(200) / 30.0
    for amplitude, rotation in ((2.0, True), (0.8, False)):
        fine = np.stack([smooth_rotations(399, rate=60.0, amplitude=amplitude, seed=s)
                         for s in range(5)])
        ref, mid = fine[:, ::2], fine[:, 1::2]
        if not rotation:
            ref, mid = ref[..., :3], mid[..., :3]
        vals = ref + np.random.default_rng(4).normal(0, 1e-5, ref.shape)
        tol = np.array([1e-3, 3e-3, 1e-2, 3e-2, 5e-2])
        slow = reduce_keys(times, ref, vals, tol, rotation, compiled=False, mid_reference=mid)
        fast = reduce_keys(times, ref, vals, tol, rotation, mid_reference=mid)
        assert np.array_equal(slow, fast)
        plain = reduce_keys(times, ref, vals, tol, rotation, compiled=False)
        if rotation:     # fast turns: the half-frames move keys, still a reduction
            assert not np.array_equal(plain, slow) and slow.sum() < 0.97 * slow.size
        else:            # LERP against the source's frames joined by LERP: frames suffice
            assert np.array_equal(plain, slow) and slow.sum() < 0.8 * slow.size


def test_a_spline_source_compresses_within_the_bound_at_its_frames():
    rig = rigedit.load_rig("quadruped")
    clips = {n: Clip(n, rig.skeleton, {k: tr.with_interpolation("catmull_rom")
                                       for k, tr in c.tracks.items()}, c.duration, c.loop)
             for n, c in rig.clips.items()}
    result = compress_clips(rig.skeleton, clips, max_error=1e-4)
    assert result.report.max_error <= 1e-4
    for name, clip in clips.items():
        err = _independent_error(rig.skeleton, clip, result.clips[name], frame_times(clip))
        assert err.max() <= 1e-4 * (1 + 1e-9)


def test_a_half_frame_nothing_mends_keeps_the_frames_and_says_so(monkeypatch):
    import rigedit.compression.pipeline as pipeline

    sk = chain(4, 0.1)
    clip = _fast_swing(sk, frames=30)
    # a check halfway that no encoding passes: the clip still comes back, held at every
    # frame, with one warning naming it
    monkeypatch.setattr(pipeline.HalfFrames, "excess",
                        lambda self, compressed: np.full(len(sk), 3 * BOUND))
    with pytest.warns(pipeline.HalfFrameWarning, match="'swing'.*every frame holds"):
        result = compress_clips(sk, {"swing": clip}, max_error=BOUND)
    err = _independent_error(sk, clip, result.clips["swing"], frame_times(clip))
    assert err.max() <= BOUND * (1 + 1e-9)
