"""The floor under a character: an opaque, unlit plane and grid lines of one colour each.

It used to be a translucent, lit plane with translucent lines: in software OpenGL that cost a
third of the editor's frame (the translucent pass) and a lit opaque one still a fifth, for a
plane of one colour. Now the plane and the lines are drawn opaque and unlit in the colours the
translucent ones showed over the background, so the picture stays (tests/test_scene.py
compares the two) for about the cost of filling the plane's pixels once (README, Speed >
Dragging). Measured here in CPU time per 1089x672 render of the quadruped: no floor 32-33 ms;
this plane 34-38 ms; the same with per-point colours about the same, with a grid texture
45-50 ms, lit 41-44 ms.

The floor follows the character (:class:`Floor`): its cells keep one size, set by the figure
(1, 2 or 5 times a power of ten, about a quarter of its largest extent), and its lines lie at
whole multiples of that size from the origin, wherever the floor is. A recording sizes it to
the clip's whole travel (:meth:`Floor.reach`), so a walk of any length stays over it while the
camera follows; the editor moves it under the figure (:meth:`Floor.follow`) in whole cells once
the figure leaves its middle half, so the lines never swim under the character, they only
appear to stay where they are while the far edge moves.
"""
from __future__ import annotations

import numpy as np
import pyvista as pv

__all__ = ["Floor", "add_floor", "floor_colors", "FLOOR_COLOR", "FLOOR_ALPHA", "GRID_COLOR",
           "GRID_ALPHA", "MAX_CELLS"]

#: The floor's plane and grid line colours and how much of them shows over the background
#: (:func:`floor_colors`): chosen so that the opaque floor shows the pixels the translucent,
#: lit floor it replaced showed over the editor's background, within a few levels
FLOOR_COLOR, FLOOR_ALPHA = "#85857f", 0.2
GRID_COLOR, GRID_ALPHA = "#6b7580", 0.55
#: The most cells along a side when the floor grows to a clip's travel: 2,002 lines, a few
#: kilometres of walk for a person-sized figure
MAX_CELLS = 1000


def _nice_cell(size):
    """Round a grid cell size to 1, 2 or 5 times a power of ten (model units)."""
    exp = np.floor(np.log10(size))
    base = size / 10 ** exp
    return float((1 if base < 1.5 else 2 if base < 3.5 else 5) * 10 ** exp)


def _grid_lines(center, sides, cell, cells):
    """The grid of a ``cells`` x ``cells`` square as ``2 (cells + 1)`` straight lines from
    edge to edge: the pixels of its cells' 3,280 edges (at 40 cells) for the vertex work of
    82 lines, which llvmpipe sets up one by one (0.8 ms a frame at 1089x672, README, Speed).

    Parameters
    ----------
    center : (3,) float
        The square's centre.
    sides : (2, 3) float
        Its two horizontal unit axes.
    cell : float
    cells : int

    Returns
    -------
    points : (4 (cells + 1), 3) float
        Two points per line: the lines along ``sides[1]``, then those along ``sides[0]``.
    lines : (6 (cells + 1),) int
        VTK's line cells.
    """
    half = 0.5 * cells * cell
    k = (np.arange(cells + 1) * cell - half)[:, None]
    a, b = sides
    ends = np.concatenate([np.stack([center + k * a - half * b, center + k * a + half * b], 1),
                           np.stack([center + k * b - half * a, center + k * b + half * a], 1)])
    n = len(ends)
    lines = np.column_stack([np.full(n, 2), 2 * np.arange(n), 2 * np.arange(n) + 1])
    return ends.reshape(-1, 3), lines.ravel()


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


class Floor:
    """The floor under a character: actors ``rig-floor`` (the plane) and ``rig-grid``.

    Parameters
    ----------
    plotter : pyvista.Plotter
        Its background is already set (the colours are blended over it).
    lo, hi : (3,) float
        Bounds of what stands on the floor (the figure): they set the cell size and the
        floor's height.
    axis : int
        Index of the vertical axis (1 for Y up, 2 for Z up).
    up : (3,) float
        The vertical unit vector.
    cells : int
        Grid cells along each side at first (and at least, after :meth:`reach`).
    style : {"plane", "lines"}
        ``"plane"`` (the editor): the plane and its grid lines; ``"lines"`` (the recorder):
        the grid lines alone.

    Attributes
    ----------
    grid_actor : vtkActor
        The grid lines.
    plane_actor : vtkActor or None
        The filled plane (style ``"plane"``).
    cell : float
        The side of a cell (model units).
    cells : int
        Cells along each side now.
    center : (3,) float
        The floor's centre, at whole cells from the origin.
    following : bool
        Whether :meth:`follow` moves the floor (the recorder, which sizes it to the whole
        travel, turns it off).
    """

    def __init__(self, plotter, lo, hi, axis, up, cells=40, style="plane"):
        if style not in ("plane", "lines"):
            raise ValueError(f"expected a floor style 'plane' or 'lines', got {style!r}")
        lo, hi = np.asarray(lo, float), np.asarray(hi, float)
        extent = float(np.max(hi - lo)) or 1.0
        # Wide enough that a walk filmed with a following camera never reaches its edge;
        # cells of a fixed size in model units so motion over the floor reads as speed.
        self.cell = _nice_cell(extent / 4.0)
        self.min_cells = self.cells = int(cells)
        self.up = np.asarray(up, float)
        self.axis = int(axis)
        self.center = np.zeros(3)
        self.center[axis] = min(0.0, lo[axis]) if lo[axis] > -0.05 * extent else lo[axis]
        self.sides = np.delete(np.eye(3), axis, axis=0)
        self.following = True
        self.grid = pv.PolyData()
        self.plane = pv.PolyData() if style == "plane" else None
        self._build()
        fill, lines = floor_colors(plotter.renderer)
        self.plane_actor = None
        if self.plane is not None:
            self.plane_actor = plotter.add_mesh(self.plane, color=fill, lighting=False,
                                                name="rig-floor", reset_camera=False,
                                                pickable=False)
        self.grid_actor = plotter.add_mesh(self.grid, color=lines, lighting=style == "lines",
                                           name="rig-grid", reset_camera=False,
                                           pickable=False)

    @property
    def size(self):
        """The side of the floor (model units)."""
        return self.cells * self.cell

    def _build(self):
        """(Re)make the plane's and the lines' points around :attr:`center`."""
        points, lines = _grid_lines(self.center, self.sides, self.cell, self.cells)
        if self.plane is not None:
            # a little above the plane (2 cm over a 20 m floor), so the depth test never
            # hides the opaque lines in it
            points = points + self.up * (1e-3 * self.size)
            half = 0.5 * self.size
            a, b = self.sides
            corners = self.center + half * np.array([-a - b, a - b, a + b, -a + b])
            self.plane.points = corners
            self.plane.faces = np.array([4, 0, 1, 2, 3])
        self.grid.points = points
        self.grid.lines = lines

    def horizontal_bounds(self):
        """(2, 2) float: the floor's lowest and highest coordinates along its two
        horizontal axes."""
        half = 0.5 * self.size
        c = self.center @ self.sides.T
        return np.array([c - half, c + half])

    def covers(self, points, margin=0.0):
        """Whether every point of ``points`` (N, 3) stands over the floor, ``margin`` model
        units inside its edge."""
        h = np.atleast_2d(np.asarray(points, float)) @ self.sides.T
        lo, hi = self.horizontal_bounds()
        return bool(np.all((h >= lo + margin) & (h <= hi - margin)))

    def reach(self, points):
        """Grow the floor (cells of the same size, lines at the same places) so that every
        point of ``points`` (N, 3), say the figure's root along a clip, stands at least a
        quarter of the first floor's side inside its edge; at most :data:`MAX_CELLS` cells
        a side. Returns whether it changed."""
        h = np.atleast_2d(np.asarray(points, float)) @ self.sides.T
        margin = 0.25 * self.min_cells * self.cell
        lo, hi = h.min(axis=0) - margin, h.max(axis=0) + margin
        mid = np.round(0.5 * (lo + hi) / self.cell) * self.cell
        half = np.max(np.maximum(hi - mid, mid - lo))
        cells = max(self.min_cells, 2 * int(np.ceil(half / self.cell)))
        cells = min(cells, MAX_CELLS)
        center = self.center.copy()
        center[self.sides.argmax(axis=1)] = mid
        if cells == self.cells and np.array_equal(center, self.center):
            return False
        self.cells, self.center = cells, center
        self._build()
        return True

    def follow(self, point):
        """Move the floor under ``point`` (3,), the figure's root, in whole cells, once it
        is out of the floor's middle half (so the figure's sway never moves it). Returns
        whether it moved."""
        if not self.following:
            return False
        off = (np.asarray(point, float) - self.center) @ self.sides.T
        if np.all(np.abs(off) <= 0.25 * self.size):
            return False
        center = self.center.copy()
        center[self.sides.argmax(axis=1)] += np.round(off / self.cell) * self.cell
        self.center = center
        self._build()
        return True


def add_floor(plotter, lo, hi, axis, up, cells=40, style="plane"):
    """The grid lines' actor of a new :class:`Floor` (which documents the parameters)."""
    return Floor(plotter, lo, hi, axis, up, cells, style).grid_actor
