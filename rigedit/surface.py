"""Surface data of a mesh beyond its shape: normals, texture coordinates and materials.

Pure numpy (no VTK). Filled by the glTF reader and written back by the glTF writer; the rig
folder format does not store it yet (a rig folder saved from a glTF keeps the shape, the
skeleton, the weights and the clips, not the materials).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Material", "Surface"]


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
