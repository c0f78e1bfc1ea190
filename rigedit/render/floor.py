"""The floor under a character: an opaque, unlit plane and grid lines of one colour each.

It used to be a translucent, lit plane with translucent lines: in software OpenGL that cost a
third of the editor's frame (the translucent pass) and a lit opaque one still a fifth, for a
plane of one colour. Now the plane and the lines are drawn opaque and unlit in the colours the
translucent ones showed over the background, so the picture stays (tests/test_scene.py
compares the two) for about the cost of filling the plane's pixels once (README, Speed >
Dragging). Measured here in CPU time per 1089x672 render of the quadruped: no floor 32-33 ms;
this plane 34-38 ms; the same with per-point colours about the same, with a grid texture
45-50 ms, lit 41-44 ms.
"""
from __future__ import annotations

import numpy as np
import pyvista as pv

__all__ = ["add_floor", "floor_colors", "FLOOR_COLOR", "FLOOR_ALPHA", "GRID_COLOR",
           "GRID_ALPHA"]

#: The floor's plane and grid line colours and how much of them shows over the background
#: (:func:`floor_colors`): chosen so that the opaque floor shows the pixels the translucent,
#: lit floor it replaced showed over the editor's background, within a few levels
FLOOR_COLOR, FLOOR_ALPHA = "#85857f", 0.2
GRID_COLOR, GRID_ALPHA = "#6b7580", 0.55


def _nice_cell(size):
    """Round a grid cell size to 1, 2 or 5 times a power of ten (model units)."""
    exp = np.floor(np.log10(size))
    base = size / 10 ** exp
    return float((1 if base < 1.5 else 2 if base < 3.5 else 5) * 10 ** exp)


def _grid_lines(plane, cells):
    """The grid of a ``cells`` x ``cells`` plane as ``2 (cells + 1)`` straight lines from edge
    to edge: the pixels of its cells' 3,280 edges (at 40 cells) for the vertex work of 82
    lines, which llvmpipe sets up one by one (0.8 ms a frame at 1089x672, README, Speed).

    Parameters
    ----------
    plane : pyvista.PolyData
        ``pv.Plane`` with ``i_resolution = j_resolution = cells``: ``(cells + 1) ** 2``
        points, row by row.
    cells : int

    Returns
    -------
    pyvista.PolyData
        ``2 (cells + 1)`` lines of two points each.
    """
    corners = np.asarray(plane.points).reshape(cells + 1, cells + 1, 3)
    ends = np.concatenate([np.stack([corners[:, 0], corners[:, -1]], axis=1),
                           np.stack([corners[0, :], corners[-1, :]], axis=1)])
    n = len(ends)
    lines = np.column_stack([np.full(n, 2), 2 * np.arange(n), 2 * np.arange(n) + 1])
    return pv.PolyData(ends.reshape(-1, 3), lines=lines.ravel())


def floor_colors(renderer):
    """Opaque colours that look like the translucent floor over the renderer's background
    (its lower colour, where the floor shows around the character).

    Returns
    -------
    plane, grid : (3,) float in [0, 1] each
        RGB of the filled plane and of the grid lines drawn over it.
    """
    behind = np.array(renderer.GetBackground())
    plane = behind + FLOOR_ALPHA * (np.array(pv.Color(FLOOR_COLOR).float_rgb) - behind)
    grid = plane + GRID_ALPHA * (np.array(pv.Color(GRID_COLOR).float_rgb) - plane)
    return plane, grid


def add_floor(plotter, lo, hi, axis, up, cells=40, style="plane"):
    """Add the floor under a character: actors ``rig-floor`` (the plane) and ``rig-grid``.

    Parameters
    ----------
    plotter : pyvista.Plotter
        Its background is already set (the colours are blended over it).
    lo, hi : (3,) float
        Bounds of what stands on the floor.
    axis : int
        Index of the vertical axis (1 for Y up, 2 for Z up).
    up : (3,) float
        The vertical unit vector.
    cells : int
        Grid cells along each side.
    style : {"plane", "lines"}
        ``"plane"`` (the editor): the plane and its grid lines; ``"lines"`` (the recorder):
        the grid lines alone.

    Returns
    -------
    vtkActor
        The grid lines' actor.
    """
    if style not in ("plane", "lines"):
        raise ValueError(f"expected a floor style 'plane' or 'lines', got {style!r}")
    extent = float(np.max(hi - lo)) or 1.0
    # Wide enough that a walk filmed with a following camera never reaches its edge;
    # cells of a fixed size in model units so motion over the floor reads as speed.
    size = cells * _nice_cell(extent / 4.0)
    ground = np.zeros(3)
    ground[axis] = min(0.0, lo[axis]) if lo[axis] > -0.05 * extent else lo[axis]
    plane = pv.Plane(center=ground, direction=up, i_size=size, j_size=size,
                     i_resolution=cells, j_resolution=cells)
    fill, lines = floor_colors(plotter.renderer)
    grid = _grid_lines(plane, cells)
    if style == "plane":
        plotter.add_mesh(pv.Plane(center=ground, direction=up, i_size=size, j_size=size,
                                  i_resolution=1, j_resolution=1),
                         color=fill, lighting=False, name="rig-floor", reset_camera=False,
                         pickable=False)
        # a little above the plane (2 cm over a 20 m floor), so the depth test never hides
        # the opaque lines in it
        grid.points += np.asarray(up, float) * (1e-3 * size)
    return plotter.add_mesh(grid, color=lines, lighting=style == "lines", name="rig-grid",
                            reset_camera=False, pickable=False)
