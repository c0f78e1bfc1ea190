"""Characters that break compressors: the bound holds on every frame of each, measured
after decoding, and what the compressor decided can be seen."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rigedit.animation import Clip, Track
from rigedit.compression import compress_clips, measure_error

from compression_characters import chain, mocap_clip, smooth_rotations

BOUND = 1e-4


def _holds(sk, clip, bound=BOUND):
    result = compress_clips(sk, {clip.name: clip}, max_error=bound)
    packed = result.clips[clip.name]
    err = measure_error(sk, clip, packed)
    assert err.max() <= bound and result.report.max_error <= bound
    return result, packed


def test_long_chain_root_error_compounds():
    # 100 joints 2 cm apart: the root's rotation error moves a point 2 m away
    sk = chain(100, 0.02)
    clip = mocap_clip(sk, frames=60, rate=30.0)
    result, packed = _holds(sk, clip)
    layout = packed.layout
    bits = {tr.joint: int(sum(tr.code.bits)) for tr in layout.animated
            if tr.channel == "rotation"}
    # tighter towards the root: the root's rotation takes more bits than the tip's
    assert bits[0] > bits[max(bits)]


def test_a_half_turn_between_two_frames():
    sk = chain(3, 0.1)
    t = np.arange(10) / 30.0
    turn = np.where(np.arange(10)[:, None] < 5, [0.0, 0, 0], [0, 0, np.pi * 0.999])
    q = Rotation.from_rotvec(turn).as_quat()
    # and a sign flip of the same rotation between frames (q and -q): not a motion at all
    q[7:] *= -1
    clip = Clip("flip", sk, {("j1", "rotation"): Track("rotation", t, q)}, loop=False)
    result, packed = _holds(sk, clip)
    assert packed.sample(t[4]).allclose(clip.sample(t[4]), atol=1e-4)
    assert packed.sample(t[5]).allclose(clip.sample(t[5]), atol=1e-4)


def test_a_joint_turning_all_the_way_round_uses_per_key_smallest_three():
    sk = chain(3, 0.1)
    t = np.arange(60) / 30.0
    angle = np.linspace(0, 4 * np.pi, 60)
    q = Rotation.from_rotvec(np.column_stack([angle, 0.3 * np.sin(angle), 0 * angle])).as_quat()
    clip = Clip("spin", sk, {("j0", "rotation"): Track("rotation", t, q)})
    _, packed = _holds(sk, clip)
    assert [tr.mode for tr in packed.layout.animated] == [4]


def test_scale_track_and_translation_only_joint():
    sk = chain(4, 0.1)
    t = np.arange(45) / 30.0
    scale = 1 + 0.3 * np.sin(3 * t)[:, None] * np.array([1, 0.5, 0])
    move = np.column_stack([0.05 * np.cos(2 * t), 0.1 + 0 * t, 0.02 * t])
    clip = Clip("stretch", sk, {("j1", "scale"): Track("scale", t, scale),
                                ("j2", "translation"): Track("translation", t, move)})
    _, packed = _holds(sk, clip)
    kinds = {(tr.joint, tr.channel) for tr in packed.layout.animated}
    assert kinds == {(1, "scale"), (2, "translation")}
    # a component that never moves takes no bits
    assert [tr.code.bits[2] for tr in packed.layout.animated if tr.channel == "scale"] == [0]


@pytest.mark.parametrize("frames", [1, 2])
def test_very_short_clips(frames):
    sk = chain(5, 0.1)
    t = np.arange(frames) / 30.0
    tracks = {(n, "rotation"): Track("rotation", t, smooth_rotations(frames, seed=i))
              for i, n in enumerate(sk.names)}
    clip = Clip("short", sk, tracks, loop=False)
    _, packed = _holds(sk, clip)
    assert packed.duration == clip.duration


def test_looping_and_non_looping_clips_wrap_and_clamp_like_the_source():
    sk = chain(6, 0.1)
    for loop in (True, False):
        clip = mocap_clip(sk, frames=50, rate=30.0, loop=loop)
        _, packed = _holds(sk, clip)
        after = [clip.duration + 0.3, -0.2, 2.5 * clip.duration]
        err = measure_error(sk, clip, packed, times=after)
        assert err.max() <= BOUND


def test_sparse_keys_are_checked_between_keys_at_the_frame_rate():
    sk = chain(4, 0.3)
    # three keys a second apart: the check runs at 30 Hz between them (frame_times)
    q = Rotation.from_rotvec([[0, 0, 0], [0, 0, 1.2], [0.5, 0, 0]]).as_quat()
    clip = Clip("sparse", sk, {("j0", "rotation"): Track("rotation", [0, 1, 2], q, "slerp")})
    result, packed = _holds(sk, clip)
    assert result.report.clips[0].frames == 61


def test_frame_rate_of_dense_and_sparse_keys():
    from rigedit.compression.frames import frame_rate
    sk = chain(2)
    q = Rotation.from_rotvec([[0, 0, 0], [0, 0, 1.2], [0.5, 0, 0]]).as_quat()
    def rate(times):
        return frame_rate(Clip("c", sk, {("j0", "rotation"): Track("rotation", times, q)}))
    assert rate([0, 0.0083333, 0.0166666]) == 120.0        # BVH's rounded frame time
    assert rate([0, 1, 2]) == 30.0
    assert rate([0, 1 / 24, 10 / 24 + 1 / 48]) == 30.0     # no rate fits: the fallback
    assert rate([0, 5 / 24, 11 / 24]) == 24.0
