"""Adversarial round trips of bezier tracks through files: clip JSON must give back the very
curves it was given (keys closer than a nanosecond, handles at exact thirds that glTF can
write exactly), and glTF's CUBICSPLINE export must be exact up to float32."""
import warnings

import numpy as np
import pytest

from builders import chain_skeleton, cylinder_rig
from rigedit.animation import Clip, Track
from rigedit.animation.curve import Curve
from rigedit.io.clip_json import load_clip, save_clip
from rigedit.io.gltf_bezier import bezier_keys
from rigedit.io.gltf_read import load_gltf
from rigedit.io.gltf_write import save_gltf


def json_round_trip(tmp_path, track, key=("j1", "translation")):
    sk = chain_skeleton(3)
    clip = Clip("c", sk, {key: track}, duration=float(track.times[-1]) + 0.1)
    path = tmp_path / "c.json"
    save_clip(path, clip)
    return load_clip(path, sk).tracks[key]


def test_clip_json_gives_back_the_same_curves_bitwise(tmp_path):
    rng = np.random.default_rng(4)
    # catmull_rom keys 1/30 s apart: handles aligned at the thirds of each segment
    track = Track("translation", np.arange(7) / 30.0, rng.normal(size=(7, 3)),
                  "catmull_rom").with_interpolation("bezier")
    assert bezier_keys(track)[2] == "CUBICSPLINE"
    back = json_round_trip(tmp_path, track)
    assert all(a == b for a, b in zip(back.curves, track.curves))    # bitwise (Curve.__eq__)
    with warnings.catch_warnings():
        warnings.simplefilter("error")        # no BezierResampledWarning: still exact
        assert bezier_keys(back)[2] == "CUBICSPLINE"


def test_a_clip_with_keys_a_fraction_of_a_nanosecond_apart_loads_again(tmp_path):
    x = Curve([0, 0.5, 0.5 + 3e-10, 1], [0, 1, 2, 3])
    track = Track.from_curves("translation", [x, Curve([0], [0.0]), Curve([0.25], [1.0])])
    back = json_round_trip(tmp_path, track)
    np.testing.assert_array_equal(back.curves[0].times, x.times)


def random_hermite_track(rng):
    """A translation track of three curves whose segments are all cubics in time (auto,
    auto_clamped and vector handles, linear segments), keys on a 30 Hz grid."""
    curves = []
    for _ in range(3):
        k = int(rng.integers(1, 8))
        t = np.sort(rng.choice(60, k, replace=False)) / 30.0
        kinds = ["auto", "auto_clamped", "vector"]
        curves.append(Curve(t, rng.normal(size=k) * 3, rng.choice(["linear", "bezier"], k),
                            left_type=rng.choice(kinds, k), right_type=rng.choice(kinds, k)))
    return Track.from_curves("translation", curves)


@pytest.mark.parametrize("seed", range(6))
def test_cubicspline_export_is_exact_up_to_float32(tmp_path, seed):
    rng = np.random.default_rng(seed)
    track = random_hermite_track(rng)
    rig = cylinder_rig(with_clip=False)
    rig.clips = {"c": Clip("c", rig.skeleton, {("j1", "translation"): track}, duration=2.0)}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = load_gltf(save_gltf(rig, tmp_path / "b.glb")).clips["c"]
    got = back.tracks[("j1", "translation")]
    assert got.interpolation == "cubic_spline"
    ts = np.linspace(0, 2, 2001)
    err = np.abs(got.sample_many(ts) - track.sample_many(ts))
    # float32 key times are rounded down by up to an ulp (1.2e-7 s below 2 s), so the
    # error is bounded by the steepest slope times that, plus float32 values
    slope = np.max(np.abs(np.diff(track.sample_many(ts), axis=0))) / (ts[1] - ts[0])
    assert err.max() <= 2.4e-7 * slope + 1e-6
