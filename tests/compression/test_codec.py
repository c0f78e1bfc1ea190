"""The decoder: compiled and numpy paths agree, bit streams round-trip, bad blobs are refused."""
import numpy as np
import pytest

from rigedit.compression import compress_clips, measure_error
from rigedit.compression.bits import pack, read_fields, words_of
from rigedit.compression.codec import kernels
from rigedit.compression.layout import LayoutError, read_clip

from compression_characters import chain, mocap_clip


def test_bit_fields_round_trip():
    rng = np.random.default_rng(3)
    widths = rng.integers(0, 33, 3000)
    values = np.array([rng.integers(0, 2 ** int(w)) if w else 0 for w in widths], np.uint64)
    start = np.concatenate([[0], np.cumsum(widths)[:-1]])
    stream = pack(values, widths)
    assert len(stream) == 4 * ((widths.sum() + 31) // 32)
    assert np.array_equal(read_fields(words_of(stream), start, widths), values)


@pytest.fixture(scope="module")
def packed():
    sk = chain(20, 0.05)
    clip = mocap_clip(sk, frames=200, loop=True)
    return compress_clips(sk, {"take": clip}, max_error=2e-4).clips["take"]


def test_compiled_decoder_matches_numpy(packed):
    if kernels() is None:
        pytest.skip("numba is not installed or RIGEDIT_NO_NUMBA is set")
    times = np.linspace(-0.5, 2 * packed.duration, 301)   # wrapped: a looping clip
    packed.use_kernels(False)
    slow = packed.sample_many(times)
    one = [packed.sample(t).as_array() for t in times[:20]]
    assert packed.use_kernels(True)
    fast = packed.sample_many(times)
    assert np.allclose(fast, slow, atol=1e-12)
    assert np.allclose([packed.sample(t).as_array() for t in times[:20]], one, atol=1e-12)


@pytest.mark.parametrize("cut", [1, 5, 17, 40])
def test_truncated_blob_is_one_layout_error(packed, cut):
    with pytest.raises(LayoutError):
        read_clip(packed.blob[:-cut], len(packed.skeleton))


def test_joint_beyond_the_skeleton_is_refused(packed):
    with pytest.raises(LayoutError, match="joint index"):
        read_clip(packed.blob, 3)


def test_compiled_reduction_keeps_the_same_keys():
    from rigedit.compression.kernels import load
    from rigedit.compression.reduce import reduce_keys
    from compression_characters import smooth_rotations

    if load("reduce_kernels") is None:
        pytest.skip("numba is not installed or RIGEDIT_NO_NUMBA is set")
    times = np.arange(200) / 120.0
    ref = np.stack([smooth_rotations(200, rate=120.0, amplitude=0.2, seed=s) for s in range(5)])
    noisy = ref + np.random.default_rng(2).normal(0, 1e-5, ref.shape)
    tol = np.array([1e-4, 3e-4, 1e-3, 1e-5, 2e-3])
    slow = reduce_keys(times, ref, noisy, tol, True, compiled=False)
    fast = reduce_keys(times, ref, noisy, tol, True)
    assert np.array_equal(slow, fast)
    vec = ref[..., :3] * 2
    assert np.array_equal(reduce_keys(times, vec, vec, tol, False, compiled=False),
                          reduce_keys(times, vec, vec, tol, False))
    kept = slow.sum(axis=1)
    assert kept[2] < 100 and kept[4] < 100 and kept[3] > kept[0] > kept[1] > kept[2]


def test_key_frames_as_steps_or_a_mask_decode_the_same():
    from rigedit.compression.layout import MASK, key_code
    sk = chain(6, 0.1)
    clip = mocap_clip(sk, frames=300)
    packed = compress_clips(sk, {"take": clip}, max_error=3e-4).clips["take"]
    frames = len(packed.layout.times)
    codes = {key_code(tr.keys, frames)[0] for tr in packed.layout.animated}
    assert MASK in codes and codes - {0, MASK}     # both kinds in one clip
    again = read_clip(packed.blob, len(sk))[0]
    for a, b in zip(packed.layout.animated, again.animated):
        assert np.array_equal(a.keys, b.keys)
    assert key_code([0, 5, 9], 10) == (3, 6) and key_code([0, 1, 2, 4, 9], 10) == (MASK, 10)


def test_segmented_tracks_decode_the_same_everywhere():
    sk = chain(10, 0.1)
    clip = mocap_clip(sk, frames=600, rate=120.0)
    packed = compress_clips(sk, {"take": clip}, max_error=1e-4).clips["take"]
    kinds = [tr.segments is not None for tr in packed.layout.animated]
    assert any(kinds)                     # long smooth tracks take segment ranges
    times = np.linspace(0, packed.duration, 97)
    packed.use_kernels(False)
    slow = packed.sample_many(times)
    plain = packed.to_clip()
    assert np.allclose(slow[40], plain.sample(times[40]).as_array(), atol=1e-12)
    if packed.use_kernels(True):
        assert np.allclose(packed.sample_many(times), slow, atol=1e-12)
    assert measure_error(sk, clip, packed).max() <= 1e-4

