"""Catmull-Rom keys: the reducer's cubic, the decoders (numpy and compiled), the plain clip
they turn into, and the layout flag agree; smooth motion keeps fewer keys than with LERP."""
import numpy as np
import pytest

from rigedit.animation import Clip, Track
from rigedit.compression import compress_clips
from rigedit.compression.codec import kernels
from rigedit.compression.cubic import hermite_cr, interpolate_cubic, neighbour_keys
from rigedit.compression.kernels import load
from rigedit.compression.layout import CUBIC, LayoutError, read_clip
from rigedit.compression.reduce import reduce_keys
from rigedit.compression.reduce_cubic import reduce_cubic

from compression_characters import chain, mocap_clip, smooth_rotations
from test_pipeline import _independent_error


def _keep(f, keys):
    keep = np.zeros((1, f), dtype=bool)
    keep[0, keys] = True
    return keep


def test_neighbour_keys_of_every_frame():
    i0, i1, i2, i3 = neighbour_keys(_keep(10, [0, 3, 7, 9]))
    assert list(i1[0]) == [0, 0, 0, 3, 3, 3, 3, 7, 7, 7]
    assert list(i2[0]) == [3, 3, 3, 7, 7, 7, 7, 9, 9, 9]
    assert list(i0[0]) == [0, 0, 0, 0, 0, 0, 0, 3, 3, 3]
    assert list(i3[0]) == [7, 7, 7, 9, 9, 9, 9, 9, 9, 9]


def test_cubic_passes_through_keys_and_reproduces_a_parabola_inside():
    times = np.arange(41) / 40.0
    values = np.column_stack([3 * times ** 2 - times, np.sin(times), times])[None]
    keys = [0, 10, 20, 30, 40]
    out = interpolate_cubic(times, values, _keep(41, keys), False)
    assert np.allclose(out[0, keys], values[0, keys], atol=0)
    # finite differences are exact on a quadratic, so interior spans reproduce it
    inner = slice(10, 31)
    assert np.allclose(out[0, inner, 0], values[0, inner, 0], atol=1e-12)
    assert np.allclose(out[0, inner, 2], values[0, inner, 2], atol=1e-12)
    # a line between the same keys misses the parabola
    assert abs(np.interp(0.375, times[keys], values[0, keys, 0]) - (3 * 0.375 ** 2 - 0.375)) > 1e-2


def test_rotation_neighbours_on_either_hemisphere_give_the_same_curve():
    q = smooth_rotations(4, rate=4.0, amplitude=0.8, seed=1)
    t = np.array([0.0, 0.3, 0.7, 1.2])
    s = np.linspace(0.3, 0.7, 9)
    args = [np.broadcast_to(x, s.shape) for x in t]
    a = hermite_cr(*args, *(np.broadcast_to(k, s.shape + (4,)) for k in q), s, True)
    flipped = q * np.array([-1, 1, -1, -1])[:, None]
    b = hermite_cr(*args, *(np.broadcast_to(k, s.shape + (4,)) for k in flipped), s, True)
    assert np.allclose(np.abs(np.sum(a * b, axis=1)), 1.0, atol=1e-12)
    assert np.allclose(np.linalg.norm(a, axis=1), 1.0)


def _swings(frames, rotation, rate=120.0):
    """Smooth swings at every frame and at every half-frame: (T, F, C), (T, F - 1, C)."""
    fine = np.stack([smooth_rotations(2 * frames - 1, rate=2 * rate, amplitude=0.3, seed=s)
                     for s in range(4)])
    if not rotation:
        fine = fine[..., :3] * 0.5
    return fine[:, ::2], fine[:, 1::2]


@pytest.mark.parametrize("rotation", [True, False])
def test_compiled_cubic_reduction_keeps_the_same_keys(rotation):
    if load("reduce_kernels") is None:
        pytest.skip("numba is not installed or RIGEDIT_NO_NUMBA is set")
    times = np.arange(300) / 120.0
    ref, mid = _swings(300, rotation)
    vals = ref + np.random.default_rng(5).normal(0, 2e-6, ref.shape)
    tol = np.array([1e-4, 5e-4, 2e-3, 2e-5])
    slow, slow_ok = reduce_cubic(times, ref, vals, tol, rotation, mid, compiled=False)
    fast, ok = reduce_cubic(times, ref, vals, tol, rotation, mid)
    assert np.array_equal(slow, fast) and np.array_equal(slow_ok, ok)
    assert ok[:3].all()
    for err in (_distance(interpolate_cubic(times, vals, fast, rotation), ref, rotation),
                _half_frame_error(times, vals, fast, mid, rotation)):
        assert np.all(err[ok] <= tol[ok, None])
    linear = reduce_keys(times, ref, vals, tol, rotation, compiled=False)
    # smooth swings: the cubic needs far fewer keys than straight lines
    assert fast[2].sum() < 0.7 * linear[2].sum()
    assert fast[1].sum() < 0.7 * linear[1].sum()


def _distance(q, ref, rotation):
    d = np.linalg.norm(q - ref, axis=-1)
    return np.minimum(d, np.linalg.norm(q + ref, axis=-1)) if rotation else d


def _half_frame_error(times, vals, keep, mid, rotation):
    """The cubic's error at every half-frame, by hand: each track's keys, the span of each
    half-frame, hermite_cr there."""
    out = np.zeros(mid.shape[:2])
    for k in range(len(vals)):
        keys = np.flatnonzero(keep[k])
        for g in range(len(times) - 1):
            s = np.searchsorted(keys, g, side="right") - 1
            idx = [keys[max(s - 1, 0)], keys[s], keys[s + 1], keys[min(s + 2, len(keys) - 1)]]
            q = hermite_cr(*(np.array(times[i]) for i in idx), *(vals[k, i] for i in idx),
                           np.array(0.5 * (times[g] + times[g + 1])), rotation)
            out[k, g] = _distance(q, mid[k, g], rotation)
    return out


def test_a_half_frame_no_key_can_mend_gives_the_track_up():
    # a source that jumps back and forth every frame: a line between frames matches it
    # between frames, a cubic through every frame overshoots halfway
    times = np.arange(40) / 30.0
    zig = np.where(np.arange(40) % 2, 1.0, -1.0)[None, :, None] * np.array([1.0, 0, 0])
    mid = np.zeros((1, 39, 3))
    keep, ok = reduce_cubic(times, zig, zig, np.array([1e-3]), False, mid, compiled=False)
    assert not ok[0]
    if load("reduce_kernels") is not None:
        keep2, ok2 = reduce_cubic(times, zig, zig, np.array([1e-3]), False, mid)
        assert not ok2[0]


def _smooth_clip(sk, frames=360, rate=120.0):
    t = np.arange(frames) / rate
    tracks = {(n, "rotation"): Track("rotation", t, smooth_rotations(frames, rate, 0.5, seed=j))
              for j, n in enumerate(sk.names)}
    tracks[(sk.names[0], "translation")] = Track(
        "translation", t, np.column_stack([0.8 * t, 0.05 * np.sin(3 * t), 0 * t]))
    return Clip("smooth", sk, tracks)


@pytest.fixture(scope="module")
def smooth():
    sk = chain(10, 0.08)
    clip = _smooth_clip(sk)
    return sk, clip, compress_clips(sk, {"smooth": clip}, max_error=5e-4)


def test_smooth_clip_is_stored_with_cubic_keys_within_the_bound(smooth):
    sk, clip, result = smooth
    packed = result.clips["smooth"]
    cubic = [tr.cubic for tr in packed.layout.animated]
    assert sum(cubic) >= len(cubic) // 2
    times = np.arange(360) / 120.0
    err = _independent_error(sk, clip, packed, times)
    assert err.max() <= 5e-4 * (1 + 1e-9)
    assert abs(err.max() - result.report.max_error) < 1e-9


def test_cubic_tracks_decode_the_same_in_every_path(smooth):
    sk, clip, result = smooth
    packed = result.clips["smooth"]
    times = np.concatenate([[-1.0, 0.0, clip.duration, clip.duration + 1],
                            np.random.default_rng(0).uniform(0, clip.duration, 200)])
    packed.use_kernels(False)
    slow = packed.sample_many(times)
    plain = packed.to_clip()
    assert any(tr.interpolation == "cubic_spline" for tr in plain.tracks.values())
    as_clip = np.array([plain.sample(t).as_array() for t in times])
    assert np.allclose(as_clip, slow, atol=1e-9)
    if kernels() is None:
        pytest.skip("numba is not installed or RIGEDIT_NO_NUMBA is set")
    assert packed.use_kernels(True)
    assert np.allclose(packed.sample_many(times), slow, atol=1e-12)
    # one pose at a time, forwards and backwards (the key cache is refilled per span)
    for t in list(times[4:40]) + list(times[40:4:-1]):
        assert np.allclose(packed.sample(t).as_array(), slow[list(times).index(t)], atol=1e-12)


def test_cubic_flag_round_trips_and_unknown_bits_are_refused(smooth):
    sk, _, result = smooth
    packed = result.clips["smooth"]
    layout, _, _ = read_clip(packed.blob, len(sk))
    assert [tr.cubic for tr in layout.animated] == [tr.cubic for tr in packed.layout.animated]
    # the first animated track's code byte: set the bit above CUBIC, which no writer sets
    blob = bytearray(packed.blob)
    at = _first_track_code(layout, blob)
    assert blob[at] & 3 == {"translation": 0, "rotation": 1, "scale": 2}[
        layout.animated[0].channel]
    assert bool(blob[at] & CUBIC) == layout.animated[0].cubic
    blob[at] |= 128
    with pytest.raises(LayoutError, match="track code"):
        read_clip(bytes(blob), len(sk))


def _first_track_code(layout, blob):
    """Byte offset of the first animated track's code byte (after its joint varint)."""
    from rigedit.compression.layout import ByteReader
    r = ByteReader(bytes(blob))
    r.take(r.varint("n", len(blob)), "name")
    r.take(9, "duration")
    r.varint("frames", 1 << 40)
    r.take(16 if layout.uniform else 4 * len(layout.times), "grid")
    for tr in range(r.varint("constant", 1 << 20)):
        r.varint("joint", 1 << 20)
        ch = r.u8("channel")
        r.take(16 if ch == 1 else 12, "value")
    r.varint("animated", 1 << 20)
    r.varint("joint", 1 << 20)
    return r.at


def test_noisy_mocap_keeps_linear_where_the_cubic_does_not_pay():
    sk = chain(6, 0.1)
    clip = mocap_clip(sk, frames=200)
    t = np.arange(200) / 120.0
    jitter = np.random.default_rng(1).normal(0, 0.02, (200, 3))
    clip.tracks[(sk.names[0], "translation")] = Track("translation", t, jitter)
    result = compress_clips(sk, {"take": clip}, max_error=1e-4)
    layout = result.clips["take"].layout
    root = [tr for tr in layout.animated if tr.channel == "translation"][0]
    assert not root.cubic              # white noise: every frame a key either way
    assert result.report.max_error <= 1e-4


def test_gltf_tracks_dense_after_reduction_key_every_frame_and_share_times():
    from rigedit.compression.encode import dense_is_cheaper

    # int16 rotations: 8 bytes a key, own times 4 more; every frame's times are shared
    assert dense_is_cheaper(70, 100, True) and not dense_is_cheaper(60, 100, True)
    assert dense_is_cheaper(80, 100, False) and not dense_is_cheaper(70, 100, False)
    sk = chain(8, 0.1)
    clip = mocap_clip(sk, frames=120)
    t = np.arange(120) / 120.0
    noise = np.random.default_rng(3).normal(0, 0.01, (120, 3))     # keeps nearly every frame
    clip.tracks[(sk.names[0], "translation")] = Track("translation", t, noise)
    result = compress_clips(sk, {"take": clip}, max_error=1e-4, target="gltf")
    tracks = result.clips["take"].clip.tracks
    lengths = {k: len(tr.times) for k, tr in tracks.items() if len(tr.times) > 1}
    dense = [k for k, n in lengths.items() if n == 120]
    assert (sk.names[0], "translation") in dense
    assert all(n == 120 or not dense_is_cheaper(n, 120, k[1] == "rotation")
               for k, n in lengths.items())
    # the report counts a shared list of times once
    assert result.report.clips[0].bytes_by_kind["times"] == 4 * sum(
        len(v) for v in {tracks[k].times.astype(np.float32).tobytes(): tracks[k].times
                         for k in lengths}.values())
    assert result.report.max_error <= 1e-4
