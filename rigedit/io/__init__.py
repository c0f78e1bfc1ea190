"""File formats -> plain data (no Qt, VTK or pyvista, but for opening a VTP mesh).

Readers return a :class:`~rigedit.io.data.RigData` (arrays, clips, a typed ``meta``) and
writers take one; :mod:`rigedit.io.registry` maps paths to them, and
``rigedit.Rig.from_data`` (above io) makes the rig. Nothing here imports the rig, the package
root or any layer above io.
"""
from .atomic import atomic_write, write_json
from .clip_json import UnknownJointsWarning, load_clip, save_clip
from .data import RigData, RigMeta, WeightsComputedWarning
from .mesh import load_mesh, save_obj
from .rig_folder import load_rig_folder, read_rig_folder, save_rig_folder
from .skeleton_json import load_skeleton, save_skeleton
from .weights_npz import load_weights, save_weights

__all__ = ["atomic_write", "write_json", "load_clip", "save_clip", "load_mesh", "save_obj",
           "RigData", "RigMeta", "read_rig_folder", "load_rig_folder", "save_rig_folder",
           "load_skeleton", "save_skeleton", "load_weights", "save_weights",
           "UnknownJointsWarning", "WeightsComputedWarning"]
