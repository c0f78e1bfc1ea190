"""The compressed skeleton's drawing: colours by error, lines, in-place updates, removal."""
import numpy as np
import pytest

from rigedit.render.compare_overlay import (COMPARE_LAYER, GREEN, RED, YELLOW, CompareOverlay,
                                            error_colors)


def _rgb(c):
    return np.round(np.asarray(c) * 255).astype(np.uint8)


def test_colours_run_green_yellow_red_and_clamp_at_the_bound():
    bound = 2e-4
    got = error_colors([0.0, bound / 2, bound, 5 * bound, bound / 4], bound)
    np.testing.assert_array_equal(got[:4], [_rgb(GREEN), _rgb(YELLOW), _rgb(RED), _rgb(RED)])
    np.testing.assert_array_equal(got[4], _rgb((np.asarray(GREEN) + YELLOW) / 2))
    warmth = [int(r) - int(g) for r, g, _ in error_colors(np.linspace(0, bound, 11), bound)]
    assert all(b > a for a, b in zip(warmth, warmth[1:]))


@pytest.fixture
def plotter():
    pv = pytest.importorskip("pyvista")
    p = pv.Plotter(off_screen=True, window_size=(200, 150))
    yield p
    p.close()


def _layers(plotter):
    rens = plotter.render_window.GetRenderers()
    rens.InitTraversal()
    return [rens.GetNextItem().GetLayer() for _ in range(rens.GetNumberOfItems())]


def test_the_overlay_updates_in_place_and_leaves_no_renderer(plotter):
    parents = np.array([-1, 0, 1, 2])
    pos = np.array([[0, 0, 0], [0, 1, 0], [0, 2, 0], [1, 2, 0]], float)
    ov = CompareOverlay(plotter, pos, parents, np.zeros(4), 1e-3, 0.05,
                        carriers=[True, False, False, False])
    assert COMPARE_LAYER in _layers(plotter)
    # the carrier root's line is left out: bones 1-2 and 2-3 only
    assert ov.bones.n_lines == 2
    array = ov.bones.GetPoints().GetData()
    moved = pos + [0.5, 0, 0]
    ov.update(moved, [0, 5e-4, 1e-3, 2e-3])
    assert ov.bones.GetPoints().GetData() is array   # written in place
    np.testing.assert_allclose(ov.positions, moved)
    np.testing.assert_allclose(ov.glyphs.positions, moved)
    np.testing.assert_array_equal(ov.colors, [_rgb(GREEN), _rgb(YELLOW), _rgb(RED), _rgb(RED)])
    plotter.render()
    ov.remove()
    assert COMPARE_LAYER not in _layers(plotter)
