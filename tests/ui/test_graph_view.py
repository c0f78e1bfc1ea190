"""The graph editor's pieces without a window: the view transform (time/value <-> pixels,
zoom, pan, framing), the grid step, which keys are drawn as a line, the polygon buffer."""
import numpy as np
import pytest

from rigedit.ui.graph_transform import MIN_TIME_SPAN, ViewTransform, grid_step


def _transform():
    tr = ViewTransform(50, 20, 800, 300)
    tr.set_window(0.0, 2.0, -10.0, 30.0)
    return tr


def test_pixels_and_data_map_both_ways_with_values_upwards():
    tr = _transform()
    t = np.array([0.0, 0.5, 2.0])
    v = np.array([-10.0, 0.0, 30.0])
    assert tr.x_of(t).tolist() == [50.0, 250.0, 850.0]
    assert tr.y_of(v).tolist() == [320.0, 245.0, 20.0]    # larger values higher up
    assert np.allclose(tr.t_of(tr.x_of(t)), t) and np.allclose(tr.v_of(tr.y_of(v)), v)
    cols = tr.column_times()
    assert len(cols) == 801 and cols[0] == 0.0 and cols[-1] == pytest.approx(2.0)


def test_zoom_keeps_the_point_under_the_mouse_and_one_axis_alone():
    tr = _transform()
    x, y = 333.0, 111.0
    t, v = float(tr.t_of(x)), float(tr.v_of(y))
    tr.zoom(2.0, x, y, time=True, value=False)
    assert tr.t1 - tr.t0 == pytest.approx(1.0) and tr.v1 - tr.v0 == pytest.approx(40.0)
    assert float(tr.t_of(x)) == pytest.approx(t) and float(tr.v_of(y)) == pytest.approx(v)
    tr.zoom(0.5, x, y, time=False, value=True)
    assert tr.v1 - tr.v0 == pytest.approx(80.0) and float(tr.v_of(y)) == pytest.approx(v)
    for _ in range(200):   # zooming in forever stops at the least span
        tr.zoom(10.0, x, y)
    assert tr.t1 - tr.t0 == pytest.approx(MIN_TIME_SPAN)


def test_pan_moves_the_content_with_the_mouse():
    tr = _transform()
    t, v = float(tr.t_of(400)), float(tr.v_of(100))
    tr.pan(40, -25)
    assert float(tr.t_of(440)) == pytest.approx(t) and float(tr.v_of(75)) == pytest.approx(v)


def test_frame_fits_the_points_with_a_margin_and_survives_one_point():
    tr = _transform()
    assert tr.frame([1.0, 3.0], [5.0, 7.0], margin=0.1)
    assert (tr.t0, tr.t1, tr.v0, tr.v1) == pytest.approx((0.8, 3.2, 4.8, 7.2))
    assert tr.frame([2.0], [4.0])
    assert tr.t0 < 2.0 < tr.t1 and tr.v0 < 4.0 < tr.v1
    assert np.isfinite([tr.t0, tr.t1, tr.v0, tr.v1]).all()
    before = (tr.t0, tr.t1)
    assert not tr.frame([np.nan], [1.0]) and (tr.t0, tr.t1) == before


@pytest.mark.parametrize("units_per_px, want", [(0.01, 0.5), (0.1, 5.0), (1.0, 50.0),
                                                 (0.003, 0.2), (2.6, 200.0)])
def test_grid_step_is_1_2_5_times_a_power_of_ten_at_least_40_px(units_per_px, want):
    step = grid_step(units_per_px, 40.0)
    assert step == pytest.approx(want)
    assert step / units_per_px >= 40.0 - 1e-9


def test_keys_closer_than_a_few_pixels_are_drawn_as_a_line():
    from rigedit.ui.graph_view import DENSE_PX, dense_mask

    xs = np.array([0.0, 20.0, 21.0, 22.5, 40.0, 80.0, 80.0 + DENSE_PX])
    ys = np.zeros(len(xs))
    assert dense_mask(xs, ys).tolist() == [False, True, True, True, False, False, False]
    ys2 = ys.copy()
    ys2[2] = 30.0    # far in value: not close although near in time
    assert dense_mask(xs, ys2).tolist() == [False, False, False, False, False, False, False]
    assert dense_mask(np.zeros(1), np.zeros(1)).tolist() == [False]


@pytest.mark.ui
def test_polygon_holds_the_points_written_through_its_buffer(qapp):
    from rigedit.ui.graph_view import polygon

    xs, ys = np.linspace(0, 1, 1000), np.linspace(5, 3, 1000)
    poly = polygon(xs, ys)
    assert poly.size() == 1000
    assert (poly[0].x(), poly[0].y()) == (0.0, 5.0)
    assert (poly[999].x(), poly[999].y()) == (1.0, 3.0)
    assert polygon([], []).size() == 0
