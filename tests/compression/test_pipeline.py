"""compress_clips: the bound holds on every frame after decoding, measured independently."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rigedit.animation import Clip, Track
from rigedit.compression import CompressedClip, compress_clips, measure_error
from rigedit.compression.frames import frame_times

from compression_characters import chain, mocap_clip


def _independent_error(skeleton, reference, candidate, times, shell=0.03):
    """Virtual vertices by hand: Clip.sample, Pose.local_matrices, Skeleton.forward per frame."""
    worst = np.zeros((len(times), len(skeleton)))
    points = np.vstack([np.eye(3) * shell, np.zeros(3)]).T  # unused origin column is harmless
    points = np.vstack([points, np.ones(4)])
    for i, t in enumerate(times):
        a = skeleton.forward(reference.sample(t).local_matrices())
        b = skeleton.forward(candidate.sample(t).local_matrices())
        worst[i] = np.linalg.norm((a - b)[:, :3] @ points[:, :3], axis=1).max(axis=1)
    return worst


@pytest.mark.parametrize("bound", [1e-4, 5e-4])
def test_bound_holds_on_every_frame(bound):
    sk = chain(12, 0.1)
    clip = mocap_clip(sk, frames=240)
    result = compress_clips(sk, {"take": clip}, max_error=bound)
    packed = result.clips["take"]
    assert isinstance(packed, CompressedClip)
    times = frame_times(clip)
    err = _independent_error(sk, clip, packed, times)
    assert err.max() <= bound * (1 + 1e-9)
    assert result.report.max_error <= bound
    assert abs(result.report.max_error - err.max()) < 1e-9
    # the compressor earns its keep: far fewer bytes than 10 float32 per joint per frame
    assert result.report.ratio > 4
    assert result.report.compressed_bytes == sum(c.compressed_bytes
                                                 for c in result.report.clips)


def test_measure_error_is_the_virtual_vertex_distance():
    sk = chain(5, 0.1)
    clip = mocap_clip(sk, frames=30, rate=30.0, root_translation=False)
    assert measure_error(sk, clip, clip).max() == 0.0
    # the root turned by a small angle more: a joint d metres out moves by ~angle * d
    angle = 1e-3
    turned = clip.copy()
    track = clip.tracks[("j0", "rotation")]
    extra = (Rotation.from_quat(track.values) * Rotation.from_rotvec([0, 0, angle])).as_quat()
    turned.set_track("j0", "rotation", Track("rotation", track.times, extra))
    err = measure_error(sk, clip, turned, shell=0.03)
    far = 0.4 + 0.03          # the last joint's farthest virtual vertex from the root
    assert np.allclose(err[:, -1].max(), angle * far, rtol=0.2)
    assert err[:, 0].max() == pytest.approx(angle * 0.03, rel=1e-3)


def test_decoded_keys_are_the_samples():
    sk = chain(6, 0.2)
    clip = mocap_clip(sk, frames=90, rate=30.0)
    packed = compress_clips(sk, {"take": clip}, max_error=2e-4).clips["take"]
    plain = packed.to_clip()
    times = np.linspace(-0.1, clip.duration + 0.2, 37)
    for t in times:
        a, b = packed.sample(t), plain.sample(t)
        assert a.allclose(b, atol=1e-12)
    batch = packed.sample_many(times)
    assert np.allclose(batch[5], packed.sample(times[5]).as_array())
    # fewer keys than frames where the motion allows
    assert sum(len(tr) for tr in plain.tracks.values()) < 90 * len(plain.tracks)


def test_constant_tracks_are_dropped_or_stored_once():
    sk = chain(4, 0.1)
    t = np.arange(20) / 30.0
    still = np.tile(Rotation.from_rotvec([0.3, 0, 0]).as_quat(), (20, 1))
    rest = np.tile([0.0, 0, 0, 1], (20, 1))
    clip = Clip("c", sk, {("j1", "rotation"): Track("rotation", t, still),
                          ("j2", "rotation"): Track("rotation", t, rest),
                          ("j3", "scale"): Track("scale", t, np.ones((20, 3)))})
    result = compress_clips(sk, {"c": clip}, max_error=1e-4)
    row = result.report.clips[0]
    assert row.tracks == {"animated": 0, "constant": 1, "omitted": 2}


@pytest.mark.parametrize("bad", [0, -1e-4, float("nan"), float("inf"), "x", None])
def test_max_error_must_be_positive_finite(bad):
    sk = chain(2)
    clip = mocap_clip(sk, frames=4)
    with pytest.raises(ValueError, match="max_error"):
        compress_clips(sk, {"take": clip}, max_error=bad)


def test_progress_is_called_rising():
    sk = chain(3)
    seen = []
    compress_clips(sk, {"a": mocap_clip(sk, 20, name="a"), "b": mocap_clip(sk, 20, name="b")},
                   progress=lambda f, s: seen.append(f))
    assert seen == sorted(seen) and seen[-1] == 1.0


def test_rigedit_compress_on_a_rig():
    import rigedit
    from builders import cylinder_rig

    rig = cylinder_rig()
    clips, report = rigedit.compress(rig, max_error=1e-4)
    assert set(clips) == {"bend"} and report.max_error <= 1e-4
    skin, _ = rigedit.compress(rig, max_error=1e-4, skin_shell=True)
    # the skin's farthest vertex from the bent joint is ~1.5 m, not 3 cm: a tighter tolerance
    assert skin["bend"].nbytes >= clips["bend"].nbytes
    with pytest.raises(ValueError, match="'nope'"):
        rigedit.compress(rig, clips=["nope"])


def test_gltf_target_keys_are_what_gltf_holds():
    from rigedit.compression import KeyedClip
    sk = chain(8, 0.1)
    clip = mocap_clip(sk, frames=120, rate=30.0)
    result = compress_clips(sk, {"take": clip}, max_error=1e-4, target="gltf")
    keyed = result.clips["take"]
    assert isinstance(keyed, KeyedClip) and result.report.max_error <= 1e-4
    assert measure_error(sk, clip, keyed).max() <= 1e-4
    plain = keyed.to_clip()
    rot = plain.tracks[("j0", "rotation")]
    assert rot.interpolation == "nlerp" and 2 <= len(rot) <= 120
    assert np.array_equal(rot.times, rot.times.astype(np.float32))
    # rotations on the normalised int16 grid (up to the unit normalisation Track applies)
    codes = rot.values * 32767
    assert np.abs(codes - np.round(codes)).max() < 2.0
    move = plain.tracks[("j0", "translation")]
    assert np.array_equal(move.values, move.values.astype(np.float32))
    with pytest.raises(ValueError, match="target"):
        compress_clips(sk, {"take": clip}, target="fbx")


def test_report_bytes_add_up_and_read_in_centimetres():
    sk = chain(5, 0.1)
    clips = {"a": mocap_clip(sk, 50, name="a"), "b": mocap_clip(sk, 80, seed=2, name="b")}
    report = compress_clips(sk, clips, max_error=2e-4).report
    assert sum(report.bytes_by_kind.values()) == report.compressed_bytes
    assert report.raw_bytes == 40 * 5 * (50 + 80)
    assert report.ratio == pytest.approx(report.raw_bytes / report.compressed_bytes)
    lines = report.lines()
    assert "bound 0.02 cm" in lines[0] and len(lines) == 2 + len(clips)
    assert report.p99_error <= report.max_error <= 2e-4
