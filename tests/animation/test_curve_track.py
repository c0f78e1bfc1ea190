"""Bezier tracks: conversion from every track mode, Euler angles per key and their
unwrapping, key edits of bezier tracks, and the clip's packed sampling."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from builders import chain_skeleton
from rigedit.animation import Clip, Track
from rigedit.animation.curve import Curve
from rigedit.animation.curve_pack import CurvePack
from rigedit.animation.curve_track import curves_from_track
from rigedit.animation.euler_curves import EULER_ORDERS, euler_to_quat, quat_to_euler
from rigedit.animation.interpolate import ROTATION_MODES, VECTOR_MODES

TIMES = np.arange(9) * 0.25


def same_rotation(a, b):
    return abs(abs(float(np.dot(a, b))) - 1) < 1e-9


@pytest.mark.parametrize("order", EULER_ORDERS)
def test_euler_round_trip_and_continuity_in_every_order(order):
    rng = np.random.default_rng(1)
    # a wandering rotation that crosses +-180 on its axes several times
    angles = np.cumsum(rng.uniform(-40, 40, (200, 3)), axis=0)
    quats = euler_to_quat(angles, order)
    back = quat_to_euler(quats, order)
    for q, e in zip(quats, euler_to_quat(back, order)):
        assert same_rotation(q, e)
    assert np.max(np.abs(np.diff(back, axis=0))) < 150   # no jumps of about 360


def test_a_spin_about_z_keeps_counting():
    quats = Rotation.from_rotvec(np.radians(90.0 * np.arange(9))[:, None] * [0, 0, 1]).as_quat()
    np.testing.assert_allclose(quat_to_euler(quats)[:, 2], 90.0 * np.arange(9), atol=1e-9)


@pytest.mark.parametrize("mode", ["step", "linear", "catmull_rom", "cubic_spline"])
def test_vector_tracks_convert_exactly(mode):
    rng = np.random.default_rng(2)
    tangents = rng.normal(size=(9, 2, 3)) if mode == "cubic_spline" else None
    track = Track("translation", TIMES, rng.normal(size=(9, 3)), mode, tangents)
    bezier = Track.from_curves("translation", curves_from_track(track))
    for t in np.linspace(-0.5, 2.5, 97):
        np.testing.assert_allclose(bezier.sample(t), track.sample(t), atol=1e-9)
    if mode == "catmull_rom":   # C1 keys: handles aligned; glTF's own tangents: free
        assert set(bezier.curves[0].left_type) == {"aligned"}
    if mode == "cubic_spline":
        assert "free" in set(bezier.curves[0].left_type)


def test_rotation_tracks_convert_through_the_keys():
    rng = np.random.default_rng(3)
    quats = Rotation.from_rotvec(rng.normal(scale=0.4, size=(9, 3))).as_quat()
    for mode, bound in (("slerp", 1.5), ("nlerp", 2.5), ("catmull_rom", 10.0)):
        track = Track("rotation", TIMES, quats, mode)
        bezier = track.with_interpolation("bezier")
        assert bezier.interpolation == "bezier" and bezier.euler_order == "XYZ"
        for t, q in zip(track.times, track.values):
            assert same_rotation(bezier.sample(t), q)
        # in between the Euler curves follow the quaternion path closely for keys 25 to 123
        # degrees apart (the bounds are what docs/curves.md states)
        mid = np.linspace(0, 2, 81)
        err = [np.degrees(2 * np.arccos(min(1, abs(np.dot(bezier.sample(t), track.sample(t))))))
               for t in mid]
        assert max(err) < bound


def test_key_edits_of_a_bezier_track():
    track = Track("translation", TIMES, np.arange(27.0).reshape(9, 3), "linear")
    b = track.with_interpolation("bezier")
    np.testing.assert_allclose(b.with_key(0.1, [7, 8, 9]).sample(0.1), [7, 8, 9])
    moved = b.with_moved_keys({0.5: 0.6})
    assert 0.6 in moved.times and 0.5 not in moved.times
    np.testing.assert_allclose(moved.sample(0.6), b.values[2])
    assert len(b.without_keys([0.5, 0.75])) == 7
    assert b.without_keys(TIMES) is None
    back = b.with_interpolation("linear")
    assert back.curves is None and back.interpolation == "linear"
    np.testing.assert_allclose(back.values, b.values)
    assert b.copy().curves == b.curves


def test_bezier_rotation_key_takes_the_euler_triple_near_the_curve():
    quats = Rotation.from_rotvec(np.radians(90.0 * np.arange(9))[:, None] * [0, 0, 1]).as_quat()
    b = Track("rotation", TIMES, quats).with_interpolation("bezier")
    keyed = b.with_key(1.6, Rotation.from_euler("z", 585, degrees=True).as_quat())
    assert keyed.curves[2].sample(1.6) == pytest.approx(585, abs=1e-6)   # not 225 or -135


def test_packed_sampling_equals_per_curve_sampling():
    rng = np.random.default_rng(4)
    curves = []
    for n in (1, 2, 5, 9):
        t = np.sort(rng.uniform(0, 3, n)) + np.arange(n) * 0.01
        c = Curve(t, rng.normal(size=n), rng.choice(["constant", "linear", "bezier"], n))
        curves.append(c.with_handle_type([0], "free").with_handle(0, "right",
                                                                 (t[0] + 0.3, 2.0)))
    pack = CurvePack(curves)
    for t in np.linspace(-1, 4, 301):
        np.testing.assert_allclose(pack.sample(t), [c.sample(t) for c in curves], atol=1e-12)


def test_a_clip_samples_bezier_tracks_as_the_tracks_do():
    sk = chain_skeleton(3)
    rng = np.random.default_rng(5)
    quats = Rotation.from_rotvec(rng.normal(scale=0.5, size=(9, 3))).as_quat()
    tracks = {("j1", "rotation"): Track("rotation", TIMES, quats).with_interpolation("bezier"),
              ("j2", "translation"): Track("translation", TIMES, rng.normal(size=(9, 3)),
                                           "catmull_rom").with_interpolation("bezier"),
              ("j0", "rotation"): Track("rotation", TIMES, quats, "slerp")}
    clip = Clip("c", sk, tracks)
    for t in np.linspace(0, 2, 23):
        pose = clip.sample(t)
        for (joint, channel), tr in tracks.items():
            got = getattr(pose, channel)[sk.index[joint]]
            np.testing.assert_allclose(np.abs(got), np.abs(tr.sample(t)), atol=1e-9)
    # an edit invalidates the pack
    clip.set_track("j2", "translation", tracks[("j2", "translation")].with_key(1.0, [5, 5, 5]))
    np.testing.assert_allclose(clip.sample(1.0).translation[sk.index["j2"]], [5, 5, 5])


def test_a_bezier_track_needs_three_curves():
    with pytest.raises(ValueError, match="3 curves"):
        Track.from_curves("translation", [Curve([0], [1])])
    with pytest.raises(ValueError, match="from curves"):
        Track("translation", [0], [[0, 0, 0]], "bezier")
    with pytest.raises(ValueError, match="Euler order"):
        Track.from_curves("rotation", [Curve([0], [1])] * 3, "XYX")


@pytest.mark.parametrize("channel, mode", [("rotation", m) for m in ROTATION_MODES]
                         + [("translation", m) for m in VECTOR_MODES])
def test_sample_many_equals_sample_per_time(channel, mode):
    rng = np.random.default_rng(6)
    times = np.array([0, 0.3, 0.5, 1.2, 1.3])
    values = (Rotation.random(5, random_state=2).as_quat() if channel == "rotation"
              else rng.normal(size=(5, 3)))
    track = Track(channel, times, values, mode)
    ts = np.linspace(-0.2, 1.5, 171)
    np.testing.assert_allclose(track.sample_many(ts), [track.sample(t) for t in ts],
                               atol=1e-12)
    bezier = track.with_interpolation("bezier")
    many, one = bezier.sample_many(ts), np.array([bezier.sample(t) for t in ts])
    if channel == "rotation":   # the same rotations (a quaternion's sign is free)
        np.testing.assert_allclose(np.abs(np.sum(many * one, axis=1)), 1, atol=1e-12)
    else:
        np.testing.assert_allclose(many, one, atol=1e-12)


@pytest.mark.parametrize("order", ["XYZ", "ZXY"])
def test_unwrap_fast_path_equals_key_by_key(order):
    from rigedit.animation.euler_curves import _triples, _unwrap_sequential, principal, unwrap
    rng = np.random.default_rng(7)
    axes = ["XYZ".index(a) for a in order]
    for scale in (5.0, 40.0):   # smooth, and wild enough to pass through gimbal lock
        angles = np.cumsum(rng.uniform(-scale, scale, (300, 3)), axis=0)
        p = principal(euler_to_quat(angles, order), order)
        ref = angles[0] + 720.0
        seq, alt = _triples(p, axes)
        np.testing.assert_allclose(unwrap(p, order, ref),
                                   _unwrap_sequential(seq, alt, axes, ref), atol=1e-9)
