"""Surface data and the one-texture view of a mesh's materials."""
from __future__ import annotations

import numpy as np

from rigedit.surface import Material, Surface, display_texture


def _sample(image, tcoords):
    """Nearest texel of (s, t) coordinates (t up the image)."""
    h, w = image.shape[:2]
    cols = np.clip((tcoords[:, 0] * w).astype(int), 0, w - 1)
    rows = np.clip(((1 - tcoords[:, 1]) * h).astype(int), 0, h - 1)
    return image[rows, cols, :3]


def test_each_part_shows_its_own_material():
    tex = np.zeros((4, 8, 4), np.uint8)
    tex[..., 3] = 255
    tex[:2, :, 0] = 255                       # top half red
    tex[2:, :, 2] = 255                       # bottom half blue
    mats = [Material("skin", np.ones(4), tex), Material("plain", [0.0, 1.0, 0.0, 1.0]),
            Material("grey", [0.2, 0.2, 0.2, 1.0])]
    uvs = np.array([[0.5, 0.25], [0.5, 0.75], [1.5, 1.25], [0.1, 0.1], [0.9, 0.9], [0.3, 0.3]])
    surf = Surface(None, uvs, vertex_primitive=[0, 0, 0, 1, 1, 2],
                   primitive_material=[0, 1, -1], materials=mats)
    image, tc = display_texture(surf, 6)
    assert image.shape == (8, 24, 4)           # three tiles: skin, plain, glTF's default white
    got = _sample(image, tc)
    assert tuple(got[0]) == (255, 0, 0) and tuple(got[1]) == (0, 0, 255)
    assert tuple(got[2]) == (255, 0, 0)        # a UV beyond 1 wraps inside its own tile
    assert tuple(got[3]) == tuple(got[4]) == (0, 255, 0)
    assert tuple(got[5]) == (255, 255, 255)


def test_one_textured_material_keeps_its_texture_and_uvs():
    tex = np.full((3, 5, 4), 200, np.uint8)
    surf = Surface(None, np.array([[0.25, 0.75], [2.0, -1.0]]), vertex_primitive=[0, 0],
                   primitive_material=[0], materials=[Material("m", [0.5, 1, 1, 1], tex)])
    image, tc = display_texture(surf, 2)
    assert image.shape == tex.shape
    np.testing.assert_allclose(tc, [[0.25, 0.25], [2.0, 2.0]])   # t = 1 - v, no wrapping
    assert image[0, 0, 0] == round(200 * round(0.5 ** (1 / 2.2) * 255) / 255)  # factor applied
    assert image[0, 0, 1] == 200
