"""CD-J2J: the joint-to-joint chamfer distance of the learned rigging papers (RigNet)."""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["cd_j2j"]


def cd_j2j(predicted, truth, diagonal):
    """Symmetric chamfer distance between two joint sets, in percent of ``diagonal``.

    The mean over predicted joints of the distance to the nearest true joint and the mean
    over true joints of the distance to the nearest predicted joint, averaged (RigNet's
    CD-J2J), divided by the bounding-box diagonal of the mesh and times 100.

    Parameters
    ----------
    predicted : (N, 3) float64
    truth : (M, 3) float64
    diagonal : float
        Bounding-box diagonal of the mesh, in the same units.

    Returns
    -------
    float
    """
    predicted = np.asarray(predicted, dtype=np.float64).reshape(-1, 3)
    truth = np.asarray(truth, dtype=np.float64).reshape(-1, 3)
    if len(predicted) == 0 or len(truth) == 0:
        raise ValueError(f"expected joints in both sets, got {len(predicted)} predicted and "
                         f"{len(truth)} true")
    if not diagonal > 0:
        raise ValueError(f"expected a positive bounding-box diagonal, got {diagonal}")
    a = cKDTree(truth).query(predicted)[0].mean()
    b = cKDTree(predicted).query(truth)[0].mean()
    return float(100.0 * 0.5 * (a + b) / diagonal)
