"""Adversarial frame times: source keys closer than a microsecond (a jump baked as two keys),
keys float32 cannot tell apart late in a long clip. The error is measured independently:
``Clip.sample`` and the compressed clip's ``sample`` at every source key time, forward
kinematics by hand, virtual vertices 3 cm along each joint's axes."""
import numpy as np
import pytest

from rigedit.animation import Clip, Track
from rigedit.compression import CompressedClip, compress_clips
from rigedit.compression.frames import frame_times
from rigedit.compression.pipeline import increasing_float32
from rigedit.model.pose import Pose

from compression_characters import chain, smooth_rotations

BOUND = 1e-4


def _model(skeleton, pose):
    """Model matrices (J, 4, 4) by a loop over parents (not Skeleton.forward)."""
    local = pose.local_matrices()
    out = np.empty_like(local)
    for j, p in enumerate(skeleton.parents):
        out[j] = local[j] if p < 0 else out[p] @ local[j]
    return out


def independent_error(skeleton, reference, candidate, times, shell=0.03):
    """Largest virtual-vertex distance over ``times`` (metres), sampled one time at a time."""
    bind = _model(skeleton, Pose(skeleton))
    offset = shell / np.linalg.norm(bind[:, :3, :3], axis=1).mean(axis=1)
    worst = 0.0
    for t in times:
        d = _model(skeleton, reference.sample(float(t))) - _model(skeleton,
                                                                 candidate.sample(float(t)))
        for axis in range(3):
            points = d[:, :3, 3] + d[:, :3, axis] * offset[:, None]
            worst = max(worst, float(np.linalg.norm(points, axis=1).max()))
    return worst


def _jump_clip(skeleton, times):
    """Every joint rotating, each key a different smooth sample: two keys close together are
    a jump of the pose within that time."""
    return Clip("take", skeleton, {
        (name, "rotation"): Track("rotation", times, smooth_rotations(len(times), seed=j))
        for j, name in enumerate(skeleton.names)})


def _irregular(extra_after, gap):
    rng = np.random.default_rng(3)
    times = np.unique(np.r_[0.0, rng.uniform(0, 2, 40), 2.0])
    return np.sort(np.r_[times, times[extra_after] + gap])


@pytest.mark.parametrize("target", ["rigedit", "gltf"])
@pytest.mark.parametrize("gap", [1e-7, 5e-7])
def test_keys_closer_than_a_microsecond_are_checked(target, gap):
    """Two keys 1e-7 s apart: the second used to be merged into the first frame, so the pose
    at its time (a source key time, one of the guarantee's frames) was never measured and
    strayed 2-3 cm at a 0.01 cm bound."""
    sk = chain(6, 0.1)
    times = _irregular(5, gap)
    clip = _jump_clip(sk, times)
    assert np.isin(times, frame_times(clip)).all()
    result = compress_clips(sk, {"take": clip}, max_error=BOUND, target=target)
    err = independent_error(sk, clip, result.clips["take"], times)
    assert err <= BOUND * (1 + 1e-9)
    assert result.report.max_error <= BOUND


@pytest.mark.parametrize("base, gap", [(100.0, 2e-6), (1000.0, 2e-5), (0.3, 1e-7)])
def test_frames_float32_cannot_keep_apart_are_stored_as_float64(base, gap):
    """Keys 2e-6 s apart at 100 s are one float32 time: the compressor wrote a blob its own
    reader refused ("frame times not finite and increasing"); 1e-7 s apart at 0.3 s float32
    moves a key by a sixth of the gap (the bound then could not be held). Both now keep
    float64 frame times, and the file reads back to the same poses."""
    sk = chain(4, 0.1)
    times = np.r_[np.linspace(0, base, 7), base + gap, base + 1.0]
    clip = _jump_clip(sk, times)
    result = compress_clips(sk, {"take": clip}, max_error=BOUND)
    packed = result.clips["take"]
    assert packed.layout.wide and packed.layout.uniform is None
    again = CompressedClip(sk, packed.blob)
    assert again.layout.wide
    np.testing.assert_array_equal(again.layout.times, packed.layout.times)
    assert independent_error(sk, clip, again, times) <= BOUND * (1 + 1e-9)
    assert result.report.clips[0].bytes_by_kind["times"] >= 8 * len(packed.layout.times)


def test_ordinary_clips_keep_float32_or_uniform_times():
    """The float64 times are only for frames float32 cannot hold: a 30 Hz clip stays a uniform
    grid, sparse irregular keys stay float32."""
    sk = chain(4, 0.1)
    uniform = _jump_clip(sk, np.arange(40) / 30.0)
    sparse = _jump_clip(sk, _irregular(5, 0.01))
    result = compress_clips(sk, {"u": uniform, "s": sparse}, max_error=BOUND)
    assert result.clips["u"].layout.uniform is not None
    assert result.clips["s"].layout.uniform is None and not result.clips["s"].layout.wide


def test_gltf_target_times_stay_strictly_increasing():
    """glTF holds float32 times only: frames float32 merges go one float32 step apart (a key
    sampler with two equal times is invalid glTF; it used to raise Track's "two keys at time
    100" out of the compressor). Such a clip is then either held or refused with the
    compressor's own message."""
    t = np.array([0.0, 100.0, 100.0 + 2e-6, 100.0 + 3e-6, 100.0 + 1e-2])
    out = increasing_float32(t)
    assert np.all(np.diff(out) > 0)
    assert np.all(out == out.astype(np.float32))
    assert np.abs(out - t).max() < 3e-5
    sk = chain(4, 0.1)
    clip = _jump_clip(sk, np.r_[np.linspace(0, 100, 7), 100 + 2e-6, 101.0])
    with pytest.raises(ValueError, match="cannot hold max_error"):
        compress_clips(sk, {"take": clip}, max_error=BOUND, target="gltf")


def test_tracks_keyed_nanoseconds_apart_stay_one_frame():
    """Tracks whose keys are a few ns apart (an FBX's tick conversion: Mixamo's clip has 461
    such pairs) are one frame each, as before: no doubled frames, the 30 Hz grid kept."""
    sk = chain(4, 0.1)
    t = np.arange(60) / 30.0
    tracks = {}
    for j, name in enumerate(sk.names):
        jitter = t + (7e-9 * j if j % 2 else 0.0)
        tracks[(name, "rotation")] = Track("rotation", jitter, smooth_rotations(60, seed=j))
    clip = Clip("take", sk, tracks)
    assert len(clip.key_times()) > 60
    assert len(frame_times(clip)) == 60
    result = compress_clips(sk, {"take": clip}, max_error=BOUND)
    assert result.clips["take"].layout.uniform is not None
    err = independent_error(sk, clip, result.clips["take"], clip.key_times())
    assert err <= BOUND * (1 + 1e-6)
