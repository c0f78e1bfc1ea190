"""The floor follows the character: a clip that walks 20 m stays over the floor in every frame
of a recording (the floor grown to the travel) and in the editor's scene (the floor moved under
the figure in whole cells, its lines where they were)."""
from __future__ import annotations

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

import imageio.v3 as iio  # noqa: E402

from rigedit.animation import Clip, Track  # noqa: E402
from rigedit.render import recorder  # noqa: E402
from rigedit.render.floor import Floor  # noqa: E402
from rigedit.render.recorder import frame_times, record_clip  # noqa: E402
from rigedit.render.scene import RigScene  # noqa: E402

WALK = 20.0   # metres, along the quadruped's front (+Z)


@pytest.fixture(scope="module")
def walker(quadruped):
    """The quadruped carried 20 m forward over 2 s by its root (a carrier on the floor)."""
    sk = quadruped.skeleton
    j = sk.index["root"]
    times = np.linspace(0.0, 2.0, 9)
    values = sk.rest_translation[j] + np.outer(times / 2.0, [0.0, 0.0, WALK])
    quadruped.clips["far"] = Clip("far", sk, {("root", "translation"):
                                              Track("translation", times, values)},
                                  duration=2.0, loop=False)
    return quadruped


def _figure(rig, clip, t):
    return rig.skin(clip.sample(t))


def test_a_recording_keeps_every_frame_over_the_floor(walker, tmp_path, monkeypatch):
    scenes = []

    class Kept(RigScene):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            scenes.append(self)

    monkeypatch.setattr(recorder, "RigScene", Kept)
    clip = walker.clips["far"]
    out = tmp_path / "far.gif"
    assert record_clip(walker, clip, out, fps=4, size=(96, 64)) == 8
    floor = scenes[0].floor
    extent = float(np.ptp(_figure(walker, clip, 0.0), axis=0).max())
    for t in frame_times(clip.duration, 4):
        assert floor.covers(_figure(walker, clip, t), margin=extent), t
    assert floor.cells > floor.min_cells     # grown: cells of the figure's size, more of them
    # and it shows: the grid lines cross the bottom rows of the last frame (under the feet;
    # measured 32% of their pixels, 2% with the floor kept at its first size and place)
    frames = iio.imread(out, index=None).astype(int)
    sky = frames[-1][0, 0]
    assert (np.abs(frames[-1][-8:] - sky).max(axis=2) > 3).mean() > 0.15


def test_the_editor_floor_moves_under_the_figure_in_whole_cells(walker):
    plotter = pv.Plotter(off_screen=True, window_size=(160, 120))
    try:
        scene = RigScene(plotter, walker)
        floor, clip = scene.floor, walker.clips["far"]
        extent = float(np.ptp(_figure(walker, clip, 0.0), axis=0).max())
        centers = [floor.center.copy()]
        for t in np.linspace(0.0, 2.0, 41):
            scene.update(clip.sample(t))
            assert floor.covers(_figure(walker, clip, t), margin=extent), t
            centers.append(floor.center.copy())
        centers = np.array(centers)
        moved = np.flatnonzero(np.any(np.diff(centers, axis=0), axis=1))
        assert 1 <= len(moved) <= 4       # a few steps over 20 m, not one per frame
        steps = np.diff(centers, axis=0)[moved] / floor.cell
        np.testing.assert_allclose(steps, np.round(steps), atol=1e-9)   # whole cells
        lines = np.unique(np.round(floor.grid.points[:, 2] / floor.cell, 6))
        np.testing.assert_allclose(lines, np.round(lines), atol=1e-6)   # lines stay put
        # walking back inside the middle half does not move it
        last = floor.center.copy()
        scene.update(clip.sample(1.9))
        np.testing.assert_array_equal(floor.center, last)
    finally:
        plotter.close()


def test_sway_inside_the_middle_does_not_move_the_floor(quadruped):
    plotter = pv.Plotter(off_screen=True, window_size=(64, 48))
    try:
        scene = RigScene(plotter, quadruped, floor_style="lines")
        start = scene.floor.center.copy()
        clip = quadruped.clips["walk"]     # 0.9 m a cycle on a 20 m floor
        for t in np.linspace(0.0, clip.duration, 12):
            scene.update(clip.sample(t))
        np.testing.assert_array_equal(scene.floor.center, start)
    finally:
        plotter.close()


def test_reach_grows_to_the_travel_with_the_same_cells():
    plotter = pv.Plotter(off_screen=True)
    try:
        floor = Floor(plotter, np.zeros(3), np.array([1.0, 2.0, 1.0]), 1, (0, 1, 0),
                      style="lines")
        cell, size = floor.cell, floor.size
        path = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 100.0], [-30.0, 0.0, 40.0]])
        assert not floor.covers(path)
        assert floor.reach(path)
        assert floor.cell == cell and floor.size > size
        assert floor.covers(path, margin=0.25 * size)
        assert floor.grid.n_lines == 2 * (floor.cells + 1)
        assert not floor.reach(path)       # already there
        assert floor.reach(np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1e9]]))
        assert floor.cells == 1000        # bounded: MAX_CELLS
    finally:
        plotter.close()


def test_a_z_up_floor_follows_in_its_own_plane():
    plotter = pv.Plotter(off_screen=True)
    try:
        floor = Floor(plotter, np.array([-0.5, -0.5, 0.0]), np.array([0.5, 0.5, 2.0]), 2,
                      (0, 0, 1))
        height = floor.center[2]
        assert not floor.follow([1.0, -2.0, 5.0])       # inside the middle half
        assert floor.follow([100.3, -47.6, 5.0])
        assert floor.center[2] == height                 # never up or down
        assert floor.covers(np.array([[100.3, -47.6, 0.0]]), margin=0.4 * floor.size)
        np.testing.assert_allclose(floor.center[:2] / floor.cell,
                                   np.round(floor.center[:2] / floor.cell), atol=1e-9)
        z = floor.plane.points[:, 2]
        np.testing.assert_allclose(z, height)             # the plane lies flat in X-Y
    finally:
        plotter.close()
