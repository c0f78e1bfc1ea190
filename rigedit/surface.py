"""Surface data of a mesh beyond its shape: normals, texture coordinates and materials.

Pure numpy (no VTK). Filled by the glTF reader and written back by the glTF writer; the rig
folder format does not store it yet (a rig folder saved from a glTF keeps the shape, the
skeleton, the weights and the clips, not the materials).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Material", "Surface", "display_texture"]


@dataclass(eq=False)
class Material:
    """A material, reduced to what rigedit shows and writes back.

    Parameters
    ----------
    name : str
    base_color : (4,) float64
        Linear RGBA base colour factor (glTF's ``baseColorFactor``).
    texture : (H, W, 4) uint8 or None
        The decoded base colour texture, rows top to bottom (as stored in the image file).
    image_bytes : bytes or None
        The encoded image file as it came in (written back unchanged on export).
    mime : str or None
        ``image/png`` or ``image/jpeg``.
    double_sided : bool
    alpha_mode : {"OPAQUE", "MASK", "BLEND"}
    """

    name: str = "material"
    base_color: np.ndarray = field(default_factory=lambda: np.ones(4))
    texture: np.ndarray = None
    image_bytes: bytes = None
    mime: str = None
    double_sided: bool = False
    alpha_mode: str = "OPAQUE"

    def __post_init__(self):
        self.base_color = np.asarray(self.base_color, dtype=np.float64).reshape(4)
        if self.texture is not None:
            self.texture = np.asarray(self.texture, dtype=np.uint8)
            if self.texture.ndim != 3 or self.texture.shape[2] != 4:
                raise ValueError(f"material {self.name!r}: expected an (H, W, 4) texture, got "
                                 f"{self.texture.shape}")


@dataclass(eq=False)
class Surface:
    """Per-vertex surface attributes of a merged mesh and the materials of its parts.

    Parameters
    ----------
    normals : (V, 3) float64 or None
    uvs : (V, 2) float64 or None
        Texture coordinates in glTF's convention (origin at the image's top-left corner,
        v pointing down).
    vertex_primitive : (V,) int32
        Which primitive (part) of the source file each vertex came from.
    primitive_material : (P,) int64
        Material index of each primitive, -1 for none.
    materials : list[Material]
    """

    normals: np.ndarray = None
    uvs: np.ndarray = None
    vertex_primitive: np.ndarray = None
    primitive_material: np.ndarray = None
    materials: list = field(default_factory=list)

    def __post_init__(self):
        if self.vertex_primitive is not None:
            self.vertex_primitive = np.asarray(self.vertex_primitive, dtype=np.int32).reshape(-1)
        if self.primitive_material is not None:
            self.primitive_material = np.asarray(self.primitive_material,
                                                 dtype=np.int64).reshape(-1)
        if self.normals is not None:
            self.normals = np.asarray(self.normals, dtype=np.float64).reshape(-1, 3)
        if self.uvs is not None:
            self.uvs = np.asarray(self.uvs, dtype=np.float64).reshape(-1, 2)

    @property
    def num_primitives(self):
        return 0 if self.primitive_material is None else len(self.primitive_material)

    def textured_material(self):
        """Index of the first material with a texture used by some primitive, or None."""
        if self.uvs is None or self.primitive_material is None:
            return None
        for m in self.primitive_material:
            if m >= 0 and self.materials[m].texture is not None:
                return int(m)
        return None


def _srgb8(linear_rgba):
    """(3,) uint8 display colour of a linear base colour factor (gamma 2.2)."""
    rgb = np.clip(np.asarray(linear_rgba, dtype=np.float64)[:3], 0.0, 1.0) ** (1 / 2.2)
    return np.round(rgb * 255).astype(np.uint8)


def display_texture(surface, num_vertices, max_size=1024):
    """One texture and per-vertex texture coordinates that show every part of a mesh in its
    own material, for a renderer that draws the mesh as one actor with one texture.

    Each material in use becomes a tile of an atlas laid side by side: its base colour
    texture times its base colour factor, or a plain tile of its factor. A vertex's
    coordinates are its UV moved into its material's tile (wrapped into the tile), or the
    tile's centre for an untextured one. With one textured material the texture is used as it
    is (no resampling, UVs unchanged so repeat wrapping stays the renderer's).

    Parameters
    ----------
    surface : Surface
    num_vertices : int
    max_size : int
        Largest tile side in an atlas of several materials.

    Returns
    -------
    image : (H, W, 4) uint8, rows top to bottom
    tcoords : (V, 2) float32
        (s, t) with t pointing up the image (VTK's convention: t = 1 - v).
    """
    prim_mat = surface.primitive_material
    used = sorted({int(m) for m in prim_mat}) if prim_mat is not None and len(prim_mat) else [-1]
    mats = {m: (surface.materials[m] if m >= 0 else Material(name="default")) for m in used}
    uvs = surface.uvs
    if len(used) == 1 and mats[used[0]].texture is not None and uvs is not None:
        mat = mats[used[0]]
        tint = _srgb8(mat.base_color).astype(np.float64) / 255.0
        image = mat.texture.copy()
        image[..., :3] = np.round(image[..., :3] * tint).astype(np.uint8)
        return image, np.column_stack([uvs[:, 0], 1.0 - uvs[:, 1]]).astype(np.float32)
    textured = [mats[m].texture for m in used if mats[m].texture is not None]
    size = min(max_size, max([max(t.shape[:2]) for t in textured], default=1))
    tiles = []
    for m in used:
        mat = mats[m]
        tile = np.empty((size, size, 4), np.uint8)
        tile[..., 3] = 255
        tile[..., :3] = _srgb8(mat.base_color)
        if mat.texture is not None:
            tex = mat.texture
            rows = (np.arange(size) * tex.shape[0] // size)
            cols = (np.arange(size) * tex.shape[1] // size)
            tile[..., :3] = np.round(tex[rows][:, cols, :3] * (tile[..., :3] / 255.0))
        tiles.append(tile)
    image = np.concatenate(tiles, axis=1)
    n = len(used)
    vertex_mat = (np.asarray(prim_mat)[surface.vertex_primitive] if prim_mat is not None
                  and len(prim_mat) else np.full(num_vertices, -1))
    k = np.searchsorted(used, vertex_mat)          # each vertex's tile (``used`` is sorted)
    has_tex = np.array([mats[m].texture is not None for m in used])[k] & (uvs is not None)
    s = np.full(num_vertices, 0.5)
    t = np.full(num_vertices, 0.5)
    if uvs is not None:
        # half a texel in from the tile's edges so filtering does not bleed from a neighbour
        inset = 0.5 / size
        s[has_tex] = inset + np.mod(uvs[has_tex, 0], 1.0) * (1 - 2 * inset)
        t[has_tex] = 1.0 - (inset + np.mod(uvs[has_tex, 1], 1.0) * (1 - 2 * inset))
    return image, np.column_stack([(k + s) / n, t]).astype(np.float32)
