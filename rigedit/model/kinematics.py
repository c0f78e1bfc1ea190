"""Forward kinematics: local pose -> model matrices -> skinning matrices (the palette)."""
from __future__ import annotations

import numpy as np

__all__ = ["local_to_model", "skinning_matrices"]


def local_to_model(skeleton, pose, out=None):
    """Model-space joint matrices of a pose.

    Parameters
    ----------
    skeleton : Skeleton
    pose : Pose
    out : (J, 4, 4) float64, optional

    Returns
    -------
    model_matrices : (J, 4, 4) float64
    """
    return skeleton.forward(pose.local_matrices(), out=out)


def skinning_matrices(skeleton, model_matrices, out=None):
    """The skinning palette ``K_j = M_j · inverse_bind_j``.

    Parameters
    ----------
    skeleton : Skeleton
    model_matrices : (J, 4, 4) float64
    out : (J, 4, 4) float64, optional

    Returns
    -------
    palette : (J, 4, 4) float64
    """
    return np.matmul(model_matrices, skeleton.inverse_bind_matrices, out=out)
