"""How the skinned mesh looks: its colour or texture, display modes, the weight heat map.

Functions that set up a mesh actor's appearance for
:class:`~rigedit.render.scene.RigScene`: the rig's surface as ``add_mesh`` arguments, the
property settings of the solid / translucent / wireframe modes, and the lookup table and
mapper settings that colour the mesh by one joint's influence. Never imports Qt.
"""
from __future__ import annotations

import pyvista as pv
from vtkmodules.vtkCommonCore import vtkLookupTable

from ..surface import display_texture

__all__ = ["MESH_COLOR", "DISPLAY_MODES", "surface_look", "set_display_mode",
           "weight_lut", "color_by_weight"]

MESH_COLOR = "#c9b79c"
DISPLAY_MODES = ("solid", "translucent", "wireframe")


def surface_look(rig, mesh):
    """``add_mesh`` colour/texture arguments from the rig's surface: its materials as one
    texture (each part in its own material's texture or base colour, see
    :func:`rigedit.surface.display_texture`), or rigedit's clay colour without a surface.
    Sets ``mesh``'s texture coordinates when there is a texture."""
    surf = getattr(rig, "surface", None)
    if surf is None:
        return {"color": MESH_COLOR}
    image, tcoords = display_texture(surf, mesh.n_points)
    mesh.active_texture_coordinates = tcoords
    return {"texture": pv.Texture(image), "color": "white"}


def set_display_mode(actor, mode):
    """Show the mesh of ``actor`` ``"solid"``, ``"translucent"`` (see-through, with its
    wireframe, so joints inside stay visible) or ``"wireframe"``."""
    if mode not in DISPLAY_MODES:
        raise ValueError(f"expected a display mode in {DISPLAY_MODES}, got {mode!r}")
    if actor is None:
        return
    prop = actor.GetProperty()
    if mode == "wireframe":
        prop.SetRepresentationToWireframe()
        prop.SetOpacity(1.0)
        prop.EdgeVisibilityOff()
        prop.SetLineWidth(1.0)
    else:
        prop.SetRepresentationToSurface()
        prop.SetOpacity(1.0 if mode == "solid" else 0.35)
        prop.SetEdgeVisibility(mode == "translucent")
        prop.SetEdgeColor(0.35, 0.33, 0.30)


def weight_lut():
    """The heat map's lookup table over [0, 1]: blue (no influence) through green and
    yellow to red (full), as painters expect."""
    lut = vtkLookupTable()
    lut.SetHueRange(0.667, 0.0)
    lut.SetSaturationRange(0.85, 0.85)
    lut.SetValueRange(0.95, 0.95)
    lut.SetNumberOfTableValues(256)
    lut.Build()
    return lut


def color_by_weight(mapper, lut, name="weight"):
    """Have ``mapper`` colour its input by the point array ``name`` (weights in [0, 1])
    through ``lut``."""
    mapper.SetLookupTable(lut)
    mapper.SetScalarModeToUsePointFieldData()
    mapper.SelectColorArray(name)
    mapper.SetScalarRange(0.0, 1.0)
    mapper.SetColorModeToMapScalars()
    mapper.ScalarVisibilityOn()
