"""The floor under a character: an opaque, unlit plane with its grid lines in a texture.

It used to be a translucent, lit plane with translucent lines: in software OpenGL that cost a
third of the editor's frame (the translucent pass) and a lit opaque one still a fifth, for a
plane of one colour. Now each point carries the colour the translucent floor showed over the
background, so the picture stays (tests/test_scene.py compares the two) at the cost of an
unlit, textured fill (README, Speed > Dragging).
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
GRID_COLOR, GRID_ALPHA = "#6b7580", 0.45
#: In the editor's textured floor, the plane's brightness relative to its lines'
LINE_SHADE = 0.75


def _nice_cell(size):
    """Round a grid cell size to 1, 2 or 5 times a power of ten (model units)."""
    exp = np.floor(np.log10(size))
    base = size / 10 ** exp
    return float((1 if base < 1.5 else 2 if base < 3.5 else 5) * 10 ** exp)


def _smoothstep(x, lo, hi):
    """(N, 1) 0 below ``lo``, 1 above ``hi``, smooth between."""
    t = np.clip((np.asarray(x, float) - lo) / (hi - lo), 0.0, 1.0)[:, None]
    return t * t * (3 - 2 * t)


def floor_colors(points, center, radius, renderer):
    """Opaque colours for the floor's points that look like a translucent floor over the
    renderer's background: the floor colour blended over the background, over its lower
    colour near the character and over the middle of a gradient background towards the
    floor's far edge (which shows near the horizon), so the floor fades into the distance.

    Parameters
    ----------
    points : (N, 3) float
    center : (3,) float
        The floor's centre, under the character.
    radius : float
        Distance from the centre at which the far colour is reached.
    renderer : vtkRenderer

    Returns
    -------
    plane, grid : (N, 3) uint8 each
        RGB of the filled plane and of the grid lines drawn over it.
    """
    near = np.array(renderer.GetBackground())
    far = 0.5 * (near + np.array(renderer.GetBackground2())) \
        if renderer.GetGradientBackground() else near
    d = np.linalg.norm(np.asarray(points, float) - center, axis=1) / radius
    behind = near + (far - near) * _smoothstep(d, 0.0, 1.0)
    plane = behind + FLOOR_ALPHA * (np.array(pv.Color(FLOOR_COLOR).float_rgb) - behind)
    grid = plane + GRID_ALPHA * (np.array(pv.Color(GRID_COLOR).float_rgb) - plane)
    return tuple(np.clip(np.rint(255 * c), 0, 255).astype(np.uint8) for c in (plane, grid))


def add_floor(plotter, lo, hi, axis, up, cells=40, style="plane"):
    """Add the floor under a character.

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
        ``"plane"`` (the editor): one opaque plane (actor ``rig-floor``) whose texture draws
        the grid lines; ``"lines"`` (the recorder): the grid lines alone (``rig-grid``).
        Lines drawn as their own actor on an opaque plane broke into dashes in the editor's
        view, hidden by the plane in the depth test even when lifted above it; in a texture
        they cannot be, and its mipmaps blend them into the plane with distance.

    Returns
    -------
    vtkActor
    """
    extent = float(np.max(hi - lo)) or 1.0
    # Wide enough that a walk filmed with a following camera never reaches its edge;
    # cells of a fixed size in model units so motion over the floor reads as speed.
    size = cells * _nice_cell(extent / 4.0)
    ground = np.zeros(3)
    ground[axis] = min(0.0, lo[axis]) if lo[axis] > -0.05 * extent else lo[axis]
    plane = pv.Plane(center=ground, direction=up, i_size=size, j_size=size,
                     i_resolution=cells, j_resolution=cells)
    fill, lines = floor_colors(plane.points, ground, size / 2, plotter.renderer)
    if style == "lines":
        grid = plane.extract_all_edges()
        grid.point_data["floor-rgb"] = floor_colors(grid.points, ground, size / 2,
                                                    plotter.renderer)[1]
        return plotter.add_mesh(grid, scalars="floor-rgb", rgb=True, lighting=False,
                                name="rig-grid", reset_camera=False, pickable=False)
    if style != "plane":
        raise ValueError(f"expected a floor style 'plane' or 'lines', got {style!r}")
    # The texture multiplies the points' colour: LINE_SHADE between the lines, 1 on them,
    # so the points carry the plane's colour brightened by 1 / LINE_SHADE.
    plane.point_data["floor-rgb"] = np.clip(np.rint(fill / LINE_SHADE), 0, 255).astype(np.uint8)
    plane.active_texture_coordinates = np.asarray(plane.active_texture_coordinates) * cells
    texels = 64   # one cell; the line two texels wide along two edges
    image = np.full((texels, texels, 3), int(round(255 * LINE_SHADE)), np.uint8)
    image[:2, :] = image[:, :2] = 255
    texture = pv.Texture(image)
    texture.repeat = texture.mipmap = texture.interpolate = True
    return plotter.add_mesh(plane, scalars="floor-rgb", rgb=True, lighting=False,
                            texture=texture, name="rig-floor", reset_camera=False,
                            pickable=False)
