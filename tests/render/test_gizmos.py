"""Joint gizmos without the editor: the ray maths of picking (pure numpy), the glyph actor's
colours, and picking and dragging on an off-screen plotter's camera."""
from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv

from rigedit.render.ray import closest_on_line, pick_sphere, sphere_entries

SIZE = (400, 300)


# ---------------------------------------------------------------------------- ray maths
def test_a_ray_through_a_sphere_picks_it_and_a_ray_beside_it_does_not():
    centers = np.array([[0.0, 0.0, 5.0], [2.0, 0.0, 5.0]])
    origin, down_z = np.zeros(3), np.array([0.0, 0.0, 1.0])
    assert pick_sphere(origin, down_z, centers, 0.5) == (0, 4.5)  # enters at z = 4.5
    j, t = pick_sphere(np.array([2.3, 0.0, 0.0]), down_z, centers, 0.5)
    assert j == 1 and t == pytest.approx(5.0 - np.sqrt(0.25 - 0.09))
    assert pick_sphere(np.array([1.0, 0.0, 0.0]), down_z, centers, 0.5) == (None, np.inf)
    assert pick_sphere(origin, down_z, np.zeros((0, 3)), 0.5) == (None, np.inf)


def test_occluded_and_overlapping_spheres_pick_the_nearest():
    down_z = np.array([0.0, 0.0, 1.0])
    # three spheres on the ray, listed far to near: the nearest wins whatever the order
    centers = np.array([[0.0, 0.0, 9.0], [0.0, 0.0, 3.0], [0.0, 0.0, 6.0]])
    assert pick_sphere(np.zeros(3), down_z, centers, 0.5)[0] == 1
    # overlapping: the ray passes 0's centre and 1's side; 1's surface is met first
    centers = np.array([[0.0, 0.0, 5.0], [0.3, 0.0, 4.7]])
    assert pick_sphere(np.zeros(3), down_z, centers, 0.5) == (1, pytest.approx(4.3))
    # ... and when the ray only grazes 1's rim, 0 (whose centre is farther) is met first
    centers = np.array([[0.0, 0.0, 5.0], [0.48, 0.0, 4.9]])
    assert pick_sphere(np.zeros(3), down_z, centers, 0.5)[0] == 0
    # a sphere behind the ray's origin is not picked, one around it is (entry behind)
    centers = np.array([[0.0, 0.0, -3.0], [0.0, 0.0, 0.2]])
    t = sphere_entries(np.zeros(3), down_z, centers, 0.5)
    assert t[0] == np.inf and t[1] == pytest.approx(-0.3)


def test_per_sphere_radius():
    centers = np.array([[0.0, 0.8, 4.0], [0.0, 0.0, 8.0]])
    down_z = np.array([0.0, 0.0, 1.0])
    assert pick_sphere(np.zeros(3), down_z, centers, np.array([0.5, 0.5]))[0] == 1
    assert pick_sphere(np.zeros(3), down_z, centers, np.array([1.0, 0.5]))[0] == 0


def test_closest_point_on_a_line_to_a_ray():
    s = closest_on_line(np.array([1.0, 2, 3]), np.array([1.0, 0, 0]),
                        np.array([4.0, 7, 10]), np.array([0.0, 0, -1]))
    assert s == pytest.approx(3.0)
    ray = np.array([1.0, 1, 0]) / np.sqrt(2)  # oblique ray from the origin
    s = closest_on_line(np.array([0.0, 5, 0]), np.array([1.0, 0, 0]), np.zeros(3), ray)
    assert s == pytest.approx(5.0)
    assert closest_on_line(np.zeros(3), np.array([1.0, 0, 0]), np.ones(3),
                           np.array([-1.0, 0, 0])) is None


# ---------------------------------------------------------------------------- glyph colours
def test_glyph_colours_follow_selection_hover_drag_and_deform_flags():
    from rigedit.render import joint_glyphs as jg

    g = jg.JointGlyphs(np.eye(3), 0.1, deform=[False, True, True])
    blue, grey = np.array(jg.SPHERE_COLOR), np.array(jg.NON_DEFORMING_COLOR)
    np.testing.assert_allclose(g.color_of(0), grey, atol=1 / 255)
    np.testing.assert_allclose(g.color_of(1), blue, atol=1 / 255)
    g.set_state(selected=1, hovered=2)
    np.testing.assert_allclose(g.color_of(1), jg.SELECTED_COLOR, atol=1 / 255)
    np.testing.assert_allclose(g.color_of(2), jg.hover_color(blue), atol=1 / 255)
    assert np.all(g.color_of(2) > blue - 1e-9) and np.any(g.color_of(2) > blue + 0.1)
    g.set_state(active=2)  # the dragged one is drawn as dragged, hovered or not
    np.testing.assert_allclose(g.color_of(2), jg.ACTIVE_COLOR, atol=1 / 255)
    g.set_state(active=None, hovered=None)
    np.testing.assert_allclose(g.color_of(2), blue, atol=1 / 255)
    g.set_deform([True, True, False])
    np.testing.assert_allclose(g.color_of(0), blue, atol=1 / 255)
    np.testing.assert_allclose(g.color_of(2), grey, atol=1 / 255)
    np.testing.assert_allclose(g.color_of(1), jg.SELECTED_COLOR, atol=1 / 255)


def test_set_positions_keeps_the_skipped_sphere():
    from rigedit.render.joint_glyphs import JointGlyphs

    g = JointGlyphs(np.zeros((3, 3)), 0.1)
    g.set_positions(np.ones((3, 3)), skip=1)
    np.testing.assert_array_equal(g.positions, [[1, 1, 1], [0, 0, 0], [1, 1, 1]])


# ---------------------------------------------------------------------------- on a camera
@pytest.fixture
def view():
    """An off-screen plotter looking down -Z at the origin, and joint gizmos in it: joints 0
    and 1 on the view axis (1 nearer), 2 off to the side."""
    from rigedit.render.joint_gizmos import JointGizmos

    p = pv.Plotter(off_screen=True, window_size=SIZE)
    positions = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.5, 0.5, 0.0]])
    g = JointGizmos(p, positions, 0.1)
    p.camera_position = [(0.0, 0.0, 10.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)]
    p.render()
    yield p, g
    g.remove()
    p.close()


def test_pick_on_screen_finds_the_nearest_joint_and_nothing_beside(view):
    _p, g = view
    x, y = g.display_position(0)
    assert g.pick(x, y) == 1  # 0 and 1 are on the same line of sight: 1 is nearer
    assert g.pick(*g.display_position(2)) == 2
    x2, y2 = g.display_position(2)
    assert g.pick((x + x2) / 2, (y + y2) / 2) is None  # empty space
    g.set_visible(False)
    assert g.pick(*g.display_position(2)) is None
    assert g.glyphs.actor in [a for a in _p.renderer.GetActors()]


def test_a_sphere_smaller_than_a_few_pixels_is_picked_within_them(view):
    p, g = view
    g.radius = 1e-4  # far under a pixel at this distance
    x, y = g.display_position(2)
    assert g.pick(x + 3, y) == 2
    assert g.pick(x + g.PICK_PIXELS + 3, y) is None
    # a larger sphere is picked on its drawn size: 0.4 units at distance 10 with a 30 degree
    # view angle over 300 pixels is 0.4 / (10 tan 15 deg) * 150 = 22 pixels
    g.radius = 0.4
    pixels = 0.4 / (10 * np.tan(np.radians(15))) * 150
    assert g.pick(x + 0.9 * pixels, y) == 2
    assert g.pick(x + 1.1 * pixels, y) is None


def test_drag_moves_in_the_view_plane_keeping_the_grab_offset(view):
    _p, g = view
    calls = []
    g.on_start = lambda j: calls.append(("start", j))
    g.on_move = lambda j, c: calls.append(("move", j, c.copy()))
    g.on_end = lambda j: calls.append(("end", j))
    x, y = g.display_position(2)
    g.start_drag(2, x + 2, y + 1)  # grabbed 2 px beside its centre
    assert g.active == 2 and calls == [("start", 2)]
    g.drag_to_pixel(x + 2 + 30, y + 1 - 20)
    c = calls[-1][2]
    assert calls[-1][:2] == ("move", 2)
    assert c[2] == pytest.approx(0.0, abs=1e-9)  # stays in the plane z = 0 (the view plane)
    nx, ny = g.display_position(2)
    assert (nx - x, ny - y) == (pytest.approx(30, abs=1e-6), pytest.approx(-20, abs=1e-6))
    np.testing.assert_allclose(g.center(2), c)
    g.end_drag()
    assert g.active is None and calls[-1] == ("end", 2)


def test_an_exception_in_a_callback_still_ends_the_drag(view):
    _p, g = view

    def broken(j):
        raise RuntimeError("boom")

    g.on_end = broken
    g.start_drag(0)
    with pytest.raises(RuntimeError):
        g.end_drag()
    assert g.active is None
