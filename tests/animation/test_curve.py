"""Bezier curves (rigedit.animation.curve): sampling, handle types, edits, easing."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigedit.animation.curve import MIN_GAP, Curve, solve_u


def bezier_at(p, u):
    """Point of the cubic Bezier with control points p (4, 2) at parameter u."""
    w = 1 - u
    return w ** 3 * p[0] + 3 * w * w * u * p[1] + 3 * w * u * u * p[2] + u ** 3 * p[3]


@pytest.fixture
def curve():
    return Curve([0, 1, 2, 3], [0, 1, 0.5, 2])


def test_the_curve_passes_through_its_keys_and_holds_beyond_them(curve):
    np.testing.assert_allclose(curve.sample(curve.times), curve.values, atol=1e-12)
    assert curve.sample(-5.0) == 0.0 and curve.sample(9.0) == 2.0
    assert isinstance(curve.sample(0.5), float) and curve.sample([0.5, 1.5]).shape == (2,)


def test_sampling_solves_x_of_u_for_handles_at_any_time_span():
    # free handles that squeeze the segment's time: x(u) is not linear in u
    c = Curve([0, 1], [0, 1], left=[[-0.1, 0], [0.05, 1]], right=[[0.9, 0], [1.1, 1]],
              left_type="free", right_type="free")
    seg = c.segments()[0]
    for u in np.linspace(0, 1, 11):
        t, v = bezier_at(seg, u)
        assert c.sample(t) == pytest.approx(v, abs=1e-9)


def test_overlapping_handles_are_scaled_so_time_stays_monotone():
    c = Curve([0, 1], [0, 1], right=[[2.0, 0], [1.5, 1]], left=[[-0.5, 0], [-1.0, 1]],
              left_type="free", right_type="free")
    x = c.segments()[0, :, 0]
    assert x[1] <= x[2] + 1e-12          # out-handle before the next key's in-handle
    t = np.linspace(0, 1, 201)
    assert np.all(np.diff(c.sample(t)) >= -1e-9)   # this S-shape stays monotone in value


def test_solve_u_on_many_curves_at_once():
    rng = np.random.default_rng(0)
    a = np.sort(rng.uniform(0, 1, (500, 2)), axis=1)
    x = np.c_[np.zeros(500), a[:, 0] * 0.9, 0.1 + a[:, 1] * 0.9, np.ones(500)]
    x[:, 2] = np.maximum(x[:, 2], x[:, 1])
    u_true = rng.uniform(0, 1, 500)
    w = 1 - u_true
    t = 3 * w * w * u_true * x[:, 1] + 3 * w * u_true ** 2 * x[:, 2] + u_true ** 3
    np.testing.assert_allclose(solve_u(x, t), u_true, atol=1e-8)


def test_constant_and_linear_segments(curve):
    c = curve.with_interpolation([0], "constant").with_interpolation([1], "linear")
    assert c.sample(0.99) == 0.0 and c.sample(1.0) == 1.0
    assert c.sample(1.5) == pytest.approx(0.75)


def test_auto_clamped_is_flat_at_extremes_and_the_ends(curve):
    # key 1 (value 1) is a maximum, key 2 (0.5) a minimum; the end keys are flat too
    for i in (0, 1, 2, 3):
        assert curve.left[i, 1] == pytest.approx(curve.values[i])
        assert curve.right[i, 1] == pytest.approx(curve.values[i])
    auto = curve.with_handle_type([1, 2], "auto")
    assert auto.right[2, 1] != pytest.approx(0.5)   # auto is not flat at key 2 ...
    assert auto.left[1, 1] == pytest.approx(1 - (0.5 - 0) / 2 / 3)   # ... nor at key 1


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-100, 100, allow_nan=False), min_size=2, max_size=8),
       st.lists(st.floats(0.05, 3.0), min_size=8, max_size=8))
def test_auto_clamped_never_overshoots_its_keys(values, gaps):
    times = np.cumsum(gaps[:len(values)])
    c = Curve(times, values)
    for k in range(len(values) - 1):
        t = np.linspace(times[k], times[k + 1], 41)
        s = c.sample(t)
        lo, hi = sorted(values[k:k + 2])
        assert np.all(s >= lo - 1e-9) and np.all(s <= hi + 1e-9)


def test_vector_handles_point_a_third_of_the_way_to_the_neighbour(curve):
    c = curve.with_handle_type([1], "vector")
    np.testing.assert_allclose(c.left[1], [1 - 1 / 3, 1 + (0 - 1) / 3])
    np.testing.assert_allclose(c.right[1], [1 + 1 / 3, 1 + (0.5 - 1) / 3])


def test_dragging_an_auto_handle_makes_both_aligned_and_collinear(curve):
    c = curve.with_handle(1, "right", (1.5, 2.0))
    assert c.left_type[1] == c.right_type[1] == "aligned"
    key = np.array([1.0, 1.0])
    d_right, d_left = c.right[1] - key, c.left[1] - key
    assert d_right[0] * d_left[1] - d_right[1] * d_left[0] == pytest.approx(0, abs=1e-12)
    assert np.dot(d_right, d_left) < 0
    # the left handle keeps its length
    assert np.hypot(*d_left) == pytest.approx(np.hypot(*(curve.left[1] - key)))
    free = c.with_handle_type([1], "free").with_handle(1, "right", (1.2, 0.0))
    np.testing.assert_allclose(free.left[1], c.left[1])
    vec = curve.with_handle_type([1], "vector").with_handle(1, "left", (0.8, 0.0))
    assert vec.left_type[1] == "free" and vec.right_type[1] == "vector"


def test_a_handle_cannot_cross_to_the_other_side_of_its_key(curve):
    c = curve.with_handle(1, "right", (0.5, 3.0))
    assert c.right[1, 0] == 1.0


def test_moved_keys_keep_their_handle_offsets_and_cannot_pass_a_neighbour(curve):
    c = curve.with_handle_type([1], "free").with_keys_moved([1], 0.25, 0.5)
    assert c.times[1] == 1.25 and c.values[1] == 1.5
    np.testing.assert_allclose(c.right[1] - [1.25, 1.5], curve.right[1] - [1, 1])
    past = curve.with_keys_moved([1], 5.0, 0)
    assert past.times[1] == pytest.approx(2 - MIN_GAP) and np.all(np.diff(past.times) > 0)
    both = curve.with_keys_moved([1, 2], 5.0, 0)    # moved together up to the next unmoved
    assert both.times[2] == pytest.approx(3 - MIN_GAP)
    assert both.times[2] - both.times[1] == pytest.approx(1.0)
    early = curve.with_keys_moved([0, 1], -5.0, 0)   # not before a clip's start
    np.testing.assert_allclose(early.times[:2], [0, 1])
    assert curve.scaled([0, 1], 2.0, 3.0, 0, 1).times[0] == 0.0


def test_insert_and_delete_keys(curve):
    c = curve.with_key(0.5)
    assert len(c) == 5 and c.values[1] == pytest.approx(curve.sample(0.5))
    assert c.left_type[1] == "auto_clamped" and c.interpolation[1] == "bezier"
    assert len(curve.with_key(1.0, 7.0)) == 4 and curve.with_key(1.0, 7.0).values[1] == 7.0
    d = curve.without_keys([1, 2])
    np.testing.assert_allclose(d.times, [0, 3])
    assert curve.without_keys(range(4)) is None


def test_a_one_key_curve(curve):
    one = Curve([0.5], [2.0])
    np.testing.assert_allclose(one.sample([0, 0.5, 9]), 2.0)
    assert len(one.with_key(1.0, 3.0)) == 2
    assert one.with_keys_moved([0], 10, 1).times[0] == 10.5
    assert one.without_keys([0]) is None


def test_easing_presets_flatten_and_lengthen_handles(curve):
    c = Curve([0, 1], [0, 1], "linear")
    ease_in = c.with_easing([1], "ease_in")
    assert ease_in.left[1, 1] == 1.0 and ease_in.left_type[1] == "free"
    assert ease_in.interpolation[0] == "bezier"
    # arriving slowly: the curve is above the straight line near the end
    assert ease_in.sample(0.9) > 0.9
    ease_out = c.with_easing([0], "ease_out")
    assert ease_out.sample(0.1) < 0.1
    both = c.with_easing([0, 1], "ease_in_out")
    assert both.sample(0.5) == pytest.approx(0.5, abs=1e-9)    # symmetric
    assert both.sample(0.1) < 0.1 and both.sample(0.9) > 0.9


def test_scaling_keys_about_a_pivot(curve):
    c = curve.scaled([1, 2], 1.0, 1.5, 0.0, 2.0)
    np.testing.assert_allclose(c.times, [0, 1, 2.5, 3])
    np.testing.assert_allclose(c.values, [0, 2, 1, 2])
    # keys are not mirrored in time: a factor <= 0 is the smallest one, order kept
    flat = curve.scaled([1, 2], 1.5, -1.0, 0.0, 1.0)
    np.testing.assert_allclose(flat.times[1:3], [1.5 - 0.5e-3, 1.5 + 0.5e-3])
    with pytest.raises(ValueError):
        curve.scaled([1], 0, np.nan, 0, 1)


def test_key_near(curve):
    assert curve.key_near(1.02, 0.98, 0.05, 0.05) == 1
    assert curve.key_near(1.5, 0.0, 0.05, 0.05) is None


def test_bad_curves_are_refused():
    for args in (([], []), ([0, 0], [1, 2]), ([0, 1], [1]), ([0, np.nan], [1, 2])):
        with pytest.raises(ValueError):
            Curve(*args)
    with pytest.raises(ValueError, match="interpolation"):
        Curve([0, 1], [0, 1], "cubic")
    with pytest.raises(ValueError, match="handle type"):
        Curve([0, 1], [0, 1], left_type="smooth")


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-2.0, 2.0), min_size=4, max_size=4),
       st.lists(st.floats(-5.0, 5.0), min_size=4, max_size=4))
def test_any_free_handles_sample_on_their_bezier(dx, dy):
    # handles anywhere (even reaching past the other key, or backwards): clamped and scaled
    # into a function of time, the samples lie on the Bezier of the corrected points
    c = Curve([0, 1], [0, 1], left=[[dx[0], dy[0]], [1 + dx[1], 1 + dy[1]]],
              right=[[dx[2], dy[2]], [1 + dx[3], 1 + dy[3]]], left_type="free",
              right_type="free")
    seg = c.segments()[0]
    assert np.all(np.diff(seg[:, 0]) >= -1e-12)   # control times in order: x(u) monotone
    for u in np.linspace(0, 1, 9):
        t, v = bezier_at(seg, u)
        assert c.sample(t) == pytest.approx(v, abs=1e-7)
