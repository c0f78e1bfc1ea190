"""The runtime model: transforms, skeleton, pose, kinematics, IK, morph targets, skinning
(LBS, DQS).

Imports numpy and scipy only (no Qt, VTK or pyvista).
"""
from .kinematics import local_to_model, skinning_matrices
from .morph import MorphTargets
from .pose import Pose
from .skeleton import Skeleton, topological_order
from .skinning import SkinBinding, dense_weights, linear_blend_skin, top_k_influences
from .transforms import compose_trs, decompose_trs, euler_to_quat, quat_to_euler

__all__ = ["Skeleton", "Pose", "SkinBinding", "local_to_model", "skinning_matrices",
           "linear_blend_skin", "top_k_influences", "dense_weights", "compose_trs",
           "decompose_trs", "euler_to_quat", "quat_to_euler", "topological_order",
           "MorphTargets"]


def __getattr__(name):
    # Compatibility: ``from rigedit.model import compute_weights`` (and METHODS, idw_weights)
    # worked before the weights moved to rigedit.binding; the import is deferred so that
    # model does not load binding (the layer above it) unless an old script asks.
    if name in ("compute_weights", "idw_weights", "METHODS"):
        from ..binding import weights

        return getattr(weights, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
