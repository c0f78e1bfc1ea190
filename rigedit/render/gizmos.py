"""The gizmo layer of the 3D view, one concept per module (this module gathers them):

- :mod:`.joint_glyphs`: all joint spheres as one glyph actor, coloured by state;
- :mod:`.joint_gizmos`: their picking and dragging (:class:`JointGizmos`, :func:`gizmo_radius`);
- :mod:`.axis_handles`: the X/Y/Z arrows at the selected joint (:class:`AxisHandles`);
- :mod:`.ray`: display/world conversions, the mouse ray, ray-sphere picking;
- :mod:`.observers`: interactor observers whose exceptions are shown, never lost;
- :mod:`.overlay`: the renderer layer drawn over the mesh.
"""
from __future__ import annotations

from .axis_handles import AXIS_COLORS, AxisHandles
from .joint_gizmos import JointGizmos, gizmo_radius
from .overlay import overlay_renderer
from .ray import display_to_world, world_to_display

__all__ = ["JointGizmos", "AxisHandles", "gizmo_radius", "overlay_renderer", "AXIS_COLORS",
           "display_to_world", "world_to_display"]
