"""Virtual vertices: the points the error is measured on (ACL's metric).

Each joint carries three orthogonal points at its shell distance (3 cm by default, or the
distance of the farthest skin vertex it moves) along its own x, y and z axes. The error of a
joint at a frame is the largest distance between where the reference and the candidate put
one of its points in MODEL space, so an error in a parent shows in every child.
"""
from __future__ import annotations

import numpy as np

from ..model.transforms import compose_trs

__all__ = ["DEFAULT_SHELL", "shell_distances", "local_offsets", "model_matrices",
           "vertex_error"]

#: ACL's default shell distance, metres.
DEFAULT_SHELL = 0.03


def check_shell(shell):
    """``shell`` as a positive finite float, ``ValueError`` otherwise."""
    try:
        value = float(shell)
    except (TypeError, ValueError):
        raise ValueError(f"expected a shell distance in metres, got {shell!r}") from None
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"expected a positive finite shell distance in metres, got {shell!r}")
    return value


def shell_distances(skeleton, shell=DEFAULT_SHELL, mesh=None):
    """Model-space shell distance of each joint, (J,) float64 metres.

    Parameters
    ----------
    skeleton : Skeleton
    shell : float
        Metres; every joint's distance without a mesh, and that of joints no vertex follows.
    mesh : (vertices (V, 3), indices (V, K), weights (V, K)), optional
        The skin at bind: a joint's distance is then its farthest influenced vertex's
        distance from the joint at bind (the issue's "skin's own vertex distances").
    """
    shell = check_shell(shell)
    dist = np.full(len(skeleton), shell)
    if mesh is None:
        return dist
    vertices, indices, weights = (np.asarray(a) for a in mesh)
    heads = skeleton.bind_matrices[:, :3, 3]
    used = weights > 0
    vert = np.repeat(np.arange(len(vertices)), indices.shape[1]).reshape(indices.shape)[used]
    joint = indices[used].astype(np.int64)
    far = np.linalg.norm(vertices[vert] - heads[joint], axis=1)
    best = np.zeros(len(skeleton))
    np.maximum.at(best, joint, far)
    return np.where(best > 0, best, dist)


def local_offsets(skeleton, distances):
    """Each joint's shell distance in its own units at bind, (J,): the model distance divided
    by the joint's bind scale (a glTF armature at 0.01 keeps its bones in centimetres)."""
    scale = np.linalg.norm(skeleton.bind_matrices[:, :3, :3], axis=1).mean(axis=1)
    return np.asarray(distances, dtype=np.float64) / np.where(scale > 1e-12, scale, 1.0)


def model_matrices(skeleton, local):
    """Model matrices of many poses: local (F, J, 10) -> (F, J, 4, 4) float64, one batched
    product per tree depth for all frames at once (:meth:`Skeleton.forward`)."""
    f, j = local.shape[:2]
    flat = local.reshape(f * j, 10)
    mats = compose_trs(flat[:, :3], flat[:, 3:7], flat[:, 7:10]).reshape(f, j, 4, 4)
    model = skeleton.forward(mats.transpose(1, 0, 2, 3))
    return model.transpose(1, 0, 2, 3)


def vertex_error(reference, candidate, offsets):
    """Per frame and joint the largest virtual-vertex distance, (F, J) float64.

    Parameters
    ----------
    reference, candidate : (F, J, 4, 4) float64
        Model matrices.
    offsets : (J,) float64
        Local shell distances (:func:`local_offsets`).
    """
    diff = reference[..., :3, :] - candidate[..., :3, :]          # (F, J, 3, 4)
    origin = diff[..., 3]
    worst = np.zeros(diff.shape[:2])
    for axis in range(3):
        point = origin + diff[..., axis] * offsets[None, :, None]
        np.maximum(worst, np.linalg.norm(point, axis=-1), out=worst)
    return worst
