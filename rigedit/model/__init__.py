"""The pure numerical model: transforms, skeleton, pose, kinematics, skinning, weights.

Imports numpy and scipy only (no Qt, VTK or pyvista).
"""
from .kinematics import local_to_model, skinning_matrices
from .pose import Pose
from .skeleton import Skeleton, topological_order
from .skinning import SkinBinding, dense_weights, linear_blend_skin, top_k_influences
from .transforms import compose_trs, decompose_trs, euler_to_quat, quat_to_euler
from .weights import METHODS, compute_weights, idw_weights

__all__ = ["Skeleton", "Pose", "SkinBinding", "local_to_model", "skinning_matrices",
           "linear_blend_skin", "top_k_influences", "dense_weights", "compute_weights",
           "idw_weights", "METHODS", "compose_trs", "decompose_trs", "euler_to_quat",
           "quat_to_euler", "topological_order"]
