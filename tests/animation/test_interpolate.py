"""Interpolation properties: keys reproduced, unit quaternions, shortest path, SLERP's constant
angular velocity, the hybrid's switch, C1 continuity of the Catmull-Rom spline."""
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from rigedit.animation.clip import Track
from rigedit.animation.interpolate import (HYBRID_THRESHOLD, MODES, ROTATION_MODES,
                                           VECTOR_MODES, catmull_rom_tangents, hybrid, nlerp,
                                           sample_track, slerp)

finite = st.floats(-10, 10, allow_nan=False)


@st.composite
def key_times(draw, min_keys=2, max_keys=6):
    gaps = draw(st.lists(st.floats(0.05, 2.0), min_size=min_keys - 1, max_size=max_keys - 1))
    start = draw(st.floats(0, 3))
    return start + np.r_[0.0, np.cumsum(gaps)]


@st.composite
def quats(draw, n):
    raw = np.array(draw(st.lists(st.lists(st.floats(-1, 1), min_size=4, max_size=4),
                                 min_size=n, max_size=n)))
    assume(np.all(np.linalg.norm(raw, axis=1) > 0.1))
    return raw / np.linalg.norm(raw, axis=1, keepdims=True)


@st.composite
def rotation_track(draw, mode):
    times = draw(key_times())
    q = draw(quats(len(times)))
    track = Track("rotation", times, q, mode)
    # aligned neighbours less than ~170 degrees apart keep the spline away from the origin
    assume(np.all(np.sum(track.values[1:] * track.values[:-1], axis=1) > 0.1))
    return track


@st.composite
def vector_track(draw, mode):
    times = draw(key_times())
    v = np.array(draw(st.lists(st.lists(finite, min_size=3, max_size=3),
                               min_size=len(times), max_size=len(times))))
    return Track("translation", times, v, mode)


def angle_between(a, b):
    return 2 * np.arccos(min(1.0, abs(float(np.dot(a, b)))))


# ---------------------------------------------------------------------------- endpoints, norms
@pytest.mark.parametrize("mode", ROTATION_MODES)
@settings(max_examples=40, deadline=None)
@given(data=st.data())
def test_rotation_keys_are_reproduced_and_samples_are_unit(mode, data):
    track = data.draw(rotation_track(mode))
    for t, q in zip(track.times, track.values):
        assert angle_between(track.sample(t), q) < 1e-6
    for t in np.linspace(track.times[0] - 0.5, track.times[-1] + 0.5, 23):
        assert np.linalg.norm(track.sample(t)) == pytest.approx(1.0, abs=1e-9)


@pytest.mark.parametrize("mode", VECTOR_MODES)
@settings(max_examples=40, deadline=None)
@given(data=st.data())
def test_vector_keys_are_reproduced_and_ends_clamp(mode, data):
    track = data.draw(vector_track(mode))
    for t, v in zip(track.times, track.values):
        np.testing.assert_allclose(track.sample(t), v, atol=1e-9)
    np.testing.assert_allclose(track.sample(track.times[0] - 1), track.values[0])
    np.testing.assert_allclose(track.sample(track.times[-1] + 1), track.values[-1])


def test_step_holds_the_previous_key():
    tr = Track("translation", [0, 1], [[0, 0, 0], [1, 2, 3]], "step")
    np.testing.assert_array_equal(tr.sample(0.999), [0, 0, 0])
    np.testing.assert_array_equal(tr.sample(1.0), [1, 2, 3])


def test_linear_is_halfway_at_midpoint():
    tr = Track("scale", [0, 2], [[1, 1, 1], [3, 5, 1]], "linear")
    np.testing.assert_allclose(tr.sample(1.0), [2, 3, 1])


# ---------------------------------------------------------------------------- shortest path
@pytest.mark.parametrize("fn", [nlerp, slerp, hybrid])
@settings(max_examples=60, deadline=None)
@given(q=quats(2), u=st.floats(0, 1))
def test_shortest_path_even_when_b_is_given_in_the_far_hemisphere(fn, q, u):
    a, b = q
    full = angle_between(a, b)
    # the arc through the sample is no longer than the shortest arc between a and b
    m = fn(a, -b if np.dot(a, b) > 0 else b, u)
    assert angle_between(a, m) + angle_between(m, b) <= full + 1e-6


def test_track_fixes_hemispheres_so_interpolation_takes_the_short_way():
    a = Rotation.from_euler("z", 10, degrees=True).as_quat()
    b = -Rotation.from_euler("z", 30, degrees=True).as_quat()    # same rotation, far side
    tr = Track("rotation", [0, 1], [a, b], "slerp")
    mid = Rotation.from_quat(tr.sample(0.5)).as_euler("xyz", degrees=True)
    np.testing.assert_allclose(mid, [0, 0, 20], atol=1e-9)


# ---------------------------------------------------------------------------- angular velocity
@settings(max_examples=40, deadline=None)
@given(q=quats(2))
def test_slerp_has_constant_angular_velocity(q):
    a, b = q
    total = angle_between(a, b)
    assume(total > 0.05)
    us = np.linspace(0, 1, 11)
    steps = [angle_between(slerp(a, b, u0), slerp(a, b, u1)) for u0, u1 in zip(us, us[1:])]
    np.testing.assert_allclose(steps, total / 10, atol=1e-7)


def test_nlerp_is_not_constant_velocity_on_a_wide_arc():
    a = np.array([0, 0, 0, 1.0])
    b = Rotation.from_euler("z", 160, degrees=True).as_quat()
    quarter = angle_between(a, nlerp(a, b, 0.25))
    assert quarter < 0.23 * np.radians(160)    # NLERP is slow near the keys; SLERP: 0.25


def test_hybrid_switches_at_the_threshold():
    a = np.array([0, 0, 0, 1.0])
    small = Rotation.from_euler("z", np.degrees(HYBRID_THRESHOLD) * 0.9, degrees=True).as_quat()
    wide = Rotation.from_euler("z", 120, degrees=True).as_quat()
    np.testing.assert_allclose(hybrid(a, small, 0.3), nlerp(a, small, 0.3))
    np.testing.assert_allclose(hybrid(a, wide, 0.3), slerp(a, wide, 0.3))
    assert not np.allclose(nlerp(a, wide, 0.3), slerp(a, wide, 0.3))


# ---------------------------------------------------------------------------- Catmull-Rom
def _velocity_jump(track, t, h=1e-5):
    # second-order one-sided differences: a first-order one errs by h * f'', which is large on
    # short segments with a big value change
    f = track.sample
    left = (3 * f(t) - 4 * f(t - h) + f(t - 2 * h)) / (2 * h)
    right = (-3 * f(t) + 4 * f(t + h) - f(t + 2 * h)) / (2 * h)
    return np.linalg.norm(left - right), np.linalg.norm(left) + np.linalg.norm(right)


@settings(max_examples=40, deadline=None)
@given(data=st.data())
def test_catmull_rom_vectors_are_c1_at_interior_keys(data):
    track = data.draw(vector_track("catmull_rom"))
    for t in track.times[1:-1]:
        jump, scale = _velocity_jump(track, t)
        assert jump <= 1e-3 * (1 + scale)


@settings(max_examples=40, deadline=None)
@given(data=st.data())
def test_catmull_rom_rotations_are_c1_at_interior_keys(data):
    track = data.draw(rotation_track("catmull_rom"))
    for t in track.times[1:-1]:
        jump, scale = _velocity_jump(track, t)
        assert jump <= 1e-3 * (1 + scale)


def test_linear_is_not_c1_so_the_c1_check_can_fail():
    track = Track("translation", [0, 1, 2], [[0, 0, 0], [1, 0, 0], [1, 1, 0]], "linear")
    jump, _ = _velocity_jump(track, 1.0)
    assert jump > 0.5


def test_catmull_rom_on_collinear_evenly_spaced_keys_is_the_line():
    times = [0, 1, 2, 3]
    v = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0.0]])
    tr = Track("translation", times, v, "catmull_rom")
    for t in np.linspace(0, 3, 13):
        np.testing.assert_allclose(tr.sample(t), [t, 0, 0], atol=1e-12)


def test_catmull_rom_is_centripetal():
    # Barry-Goldman tangent at the middle key with alpha 0.5 on an uneven corner, checked
    # against the pyramidal (recursive) definition evaluated numerically at the knot.
    p = np.array([[0, 0.0], [1, 0.0], [1.2, 3.0]])
    times = np.array([0.0, 1.0, 2.0])
    tan = catmull_rom_tangents(times, p)[1]
    k = np.r_[0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1) ** 0.5)]
    phantom = 2 * p[2] - p[1]
    pts = np.vstack([p, phantom])
    kn = np.r_[k, k[2] + k[2] - k[1]]

    def pyramid(s):
        p0, p1, p2, p3 = pts
        t0, t1, t2, t3 = kn
        a1 = (t1 - s) / (t1 - t0) * p0 + (s - t0) / (t1 - t0) * p1
        a2 = (t2 - s) / (t2 - t1) * p1 + (s - t1) / (t2 - t1) * p2
        a3 = (t3 - s) / (t3 - t2) * p2 + (s - t2) / (t3 - t2) * p3
        b1 = (t2 - s) / (t2 - t0) * a1 + (s - t0) / (t2 - t0) * a2
        b2 = (t3 - s) / (t3 - t1) * a2 + (s - t1) / (t3 - t1) * a3
        return (t2 - s) / (t2 - t1) * b1 + (s - t1) / (t2 - t1) * b2

    h = 1e-6
    dk = (pyramid(k[1] + h) - pyramid(k[1])) / h        # derivative w.r.t. the knot
    rate = (k[2] - k[0]) / (times[2] - times[0])
    np.testing.assert_allclose(tan, dk * rate, rtol=1e-4)


def test_catmull_rom_with_repeated_values_stays_finite():
    tr = Track("translation", [0, 1, 2, 3], [[0, 0, 0], [0, 0, 0], [0, 0, 0], [1, 0, 0]],
               "catmull_rom")
    assert np.all(np.isfinite([tr.sample(t) for t in np.linspace(0, 3, 31)]))


def test_sample_track_without_baked_tangents_matches_baked():
    times = np.array([0, 0.4, 1.0, 1.3, 2.0])
    v = np.random.default_rng(0).normal(size=(5, 3))
    tan = catmull_rom_tangents(times, v)
    for t in np.linspace(0, 2, 17):
        np.testing.assert_allclose(sample_track(times, v, t, "catmull_rom", False),
                                   sample_track(times, v, t, "catmull_rom", False, tan))


def test_modes_are_validated_per_channel():
    with pytest.raises(ValueError, match="interpolation"):
        Track("translation", [0, 1], np.zeros((2, 3)), "slerp")
    with pytest.raises(ValueError, match="interpolation"):
        Track("rotation", [0, 1], [[0, 0, 0, 1]] * 2, "cubic")
    assert Track("rotation", [0], [[0, 0, 0, 1]], "linear").interpolation == "nlerp"
    assert set(VECTOR_MODES) | set(ROTATION_MODES) == set(MODES)


def test_catmull_rom_closed_track_is_c1_across_the_loop_point():
    times = np.array([0.0, 0.3, 0.9, 1.2, 2.0])
    v = np.array([[0, 0, 0], [1, 0.5, 0], [1.5, -0.2, 0.3], [0.4, 0.8, 0], [0, 0, 0.0]])
    tr = Track("translation", times, v, "catmull_rom")
    h = 1e-5
    f = tr.sample
    end_velocity = (3 * f(2.0) - 4 * f(2.0 - h) + f(2.0 - 2 * h)) / (2 * h)
    start_velocity = (-3 * f(0.0) + 4 * f(h) - f(2 * h)) / (2 * h)
    np.testing.assert_allclose(end_velocity, start_velocity, rtol=1e-3, atol=1e-3)
    # an open track keeps secant end slopes, which differ here: the check can fail
    open_tr = Track("translation", times, np.vstack([v[:-1], [[0.1, 0, 0]]]), "catmull_rom")
    g = open_tr.sample
    end_open = (3 * g(2.0) - 4 * g(2.0 - h) + g(2.0 - 2 * h)) / (2 * h)
    start_open = (-3 * g(0.0) + 4 * g(h) - g(2 * h)) / (2 * h)
    assert np.linalg.norm(end_open - start_open) > 0.5
