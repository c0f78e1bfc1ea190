"""File formats -> plain data (no Qt, VTK or pyvista, but for opening a VTP mesh)."""
from .atomic import atomic_write, write_json
from .clip_json import UnknownJointsWarning, load_clip, save_clip
from .mesh import load_mesh, save_obj
from .rig_folder import WeightsComputedWarning, load_rig_folder, save_rig_folder
from .skeleton_json import load_skeleton, save_skeleton
from .weights_npz import load_weights, save_weights

__all__ = ["atomic_write", "write_json", "load_clip", "save_clip", "load_mesh", "save_obj",
           "load_rig_folder", "save_rig_folder", "load_skeleton", "save_skeleton",
           "load_weights", "save_weights", "UnknownJointsWarning", "WeightsComputedWarning"]
