"""Adversarial key edits of curves: scaling about a cursor by any factor, keys squeezed
against their neighbours, keys closer than MIN_GAP (a file may hold them), moved keys that
must neither swap, merge nor drift in time when only their value moves."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rigedit.animation.curve import MIN_GAP, Curve


def check_edit(before, after, idx):
    """The edit kept the keys in order (strictly increasing), the unmoved keys where they
    were (bitwise) and every key at or after time 0."""
    assert len(after) == len(before)
    assert np.all(np.diff(after.times) > 0)
    fixed = np.setdiff1d(np.arange(len(before)), idx)
    np.testing.assert_array_equal(after.times[fixed], before.times[fixed])
    assert after.times.min() >= min(0.0, before.times.min())


def test_scaling_keys_far_past_a_neighbour_squeezes_them_in_order():
    c = Curve([0, 0.1, 0.2, 0.3, 1.0], [0, 1, 2, 3, 4])
    # x100 about 0 throws keys 1..3 to 10, 20, 30: each stops before the key at 1.0
    out = c.scaled([1, 2, 3], 0.0, 100.0, 0.0, 1.0)
    check_edit(c, out, [1, 2, 3])
    np.testing.assert_allclose(out.times[1:4], 1.0 - MIN_GAP * np.array([3, 2, 1]))
    np.testing.assert_array_equal(out.values, c.values)   # order kept: values follow


@pytest.mark.parametrize("factor", [0.0, -1.0, -1e9, 1e-12, 1e9])
@pytest.mark.parametrize("pivot", [-3.0, 0.0, 0.15, 0.9999, 1.0, 5.0])
def test_scaling_by_any_factor_about_any_cursor_keeps_a_valid_curve(factor, pivot):
    c = Curve([0, 0.1, 0.2, 0.3, 1.0, 1.05], [0, 1, 2, 3, 4, 5])
    for idx in ([1, 2, 3], [0, 1, 2, 3, 4, 5], [4, 5], [0], [1, 3, 5]):
        check_edit(c, c.scaled(idx, pivot, factor, 0.0, 1.0), idx)


def test_moving_only_the_value_of_a_key_a_nanosecond_from_its_neighbour():
    # a clip file may hold keys 1e-9 s apart (strictly increasing is all it asks)
    c = Curve([0, 1e-9, 2e-9, 1.0], [0, 1, 2, 3])
    for i in range(4):
        out = c.with_keys_moved([i], 0.0, 0.5)     # a value-only move: no time change
        np.testing.assert_array_equal(out.times, c.times)
        assert out.values[i] == c.values[i] + 0.5
    # moving in time towards the close neighbour does not bring it closer ...
    out = c.with_keys_moved([1], -1.0, 0.0)
    np.testing.assert_array_equal(out.times, c.times)
    # ... away from it goes at most MIN_GAP short of the next unmoved key
    out = c.with_keys_moved([2], 5.0, 0.0)
    assert out.times[2] == pytest.approx(1.0 - MIN_GAP)


def test_scaling_keys_a_nanosecond_apart_by_one_leaves_them_apart():
    c = Curve([0, 1e-9, 2e-9, 3e-9, 1.0], [0, 1, 2, 3, 4])
    out = c.scaled([1, 2], 0.5, 1.0, 0.0, 1.0)
    check_edit(c, out, [1, 2])
    np.testing.assert_allclose(out.times, c.times, atol=1e-15)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.floats(1e-9, 0.5), min_size=2, max_size=9),
       st.lists(st.booleans(), min_size=9, max_size=9),
       st.floats(-2.0, 4.0), st.floats(-1e3, 1e3), st.floats(-5.0, 5.0))
def test_random_moves_and_scales_never_break_the_curve(gaps, chosen, pivot, factor, dt):
    times = np.cumsum(gaps) - gaps[0]
    c = Curve(times, np.arange(len(times), dtype=float))
    idx = np.flatnonzero(chosen[:len(times)])
    if len(idx) == 0:
        idx = np.array([len(times) // 2])
    check_edit(c, c.scaled(idx, pivot, factor, 0.0, 1.0), idx)
    assert c.scaled(idx, pivot, 1.0, dt, 1.0) == c       # a factor of 1: bitwise the same
    low, high = c.shift_range(idx)
    assert low <= 0.0 <= high
    moved = c.with_keys_moved(idx, dt, 1.0)
    check_edit(c, moved, idx)
    shift = moved.times[idx] - c.times[idx]
    np.testing.assert_allclose(shift, shift[0], atol=1e-12)   # one offset for all moved keys
    assert abs(shift[0]) <= abs(dt) + 1e-15                  # clamped, never overshot
    assert shift[0] == pytest.approx(np.clip(dt, low, high), abs=1e-12)
