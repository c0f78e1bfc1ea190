"""The template's joints at the embedded positions, their frames turned as the template's
bones are (step 4 of :mod:`.pipeline`).

A joint's model-space rest rotation is the template's, turned by the smallest rotation
taking the template's bone to the embedded one (for a joint with several children, the
rotation that best takes all its child bones to theirs; a leaf keeps its parent's turn; a
root keeps the template's frame). So bone rolls stay as the template's animator made them,
and the template's clips mean the same motion.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from .templates import rest_model

__all__ = ["build_skeleton"]


def build_skeleton(template, positions):
    """The template's joints at new positions, frames turned as the module notes say.

    Parameters
    ----------
    template : Skeleton
    positions : (J, 3) float64
        Model-space position of every template joint, template order.

    Returns
    -------
    Skeleton
    """
    from ...model.skeleton import Skeleton

    positions = np.asarray(positions, dtype=np.float64)
    rest = rest_model(template)
    t_pos = rest[:, :3, 3]
    t_rot = Rotation.from_matrix(rest[:, :3, :3]).as_matrix()  # scale dropped
    n = len(template)
    turn = np.tile(np.eye(3), (n, 1, 1))
    t_len = e_len = 0.0
    for j in range(n):
        p = template.parents[j]
        kids = template.children(j)
        a = t_pos[kids] - t_pos[j]
        b = positions[kids] - positions[j]
        ok = (np.linalg.norm(a, axis=1) > 1e-9) & (np.linalg.norm(b, axis=1) > 1e-9)
        t_len += np.linalg.norm(a, axis=1).sum()
        e_len += np.linalg.norm(b, axis=1).sum()
        if p < 0:
            continue                       # a root keeps the template's frame (its facing)
        if not ok.any():
            turn[j] = turn[p]              # a leaf turns with its parent
            continue
        w = np.linalg.norm(b[ok], axis=1)
        r, _ = Rotation.align_vectors(b[ok], a[ok], weights=w if ok.sum() > 1 else None)
        turn[j] = r.as_matrix()
    model_rot = turn @ t_rot
    local_t = np.empty((n, 3))
    local_r = np.empty((n, 3, 3))
    for j in range(n):
        p = template.parents[j]
        if p < 0:
            local_t[j], local_r[j] = positions[j], model_rot[j]
        else:
            local_t[j] = model_rot[p].T @ (positions[j] - positions[p])
            local_r[j] = model_rot[p].T @ model_rot[j]
    scale = e_len / t_len if t_len > 0 else 1.0
    tails = np.full((n, 3), np.nan)
    has = np.all(np.isfinite(template.tails), axis=1)
    if has.any():
        # tails are given at bind time: carried to the rest pose by their joint, then taken
        # relative to the rest head, turned and scaled
        bind_local = np.einsum("tij,tj->ti", template.inverse_bind_matrices[has],
                               np.c_[template.tails[has], np.ones(has.sum())])
        t_tails = np.einsum("tij,tj->ti", rest[has], bind_local)[:, :3]
        tails[has] = positions[has] + scale * np.einsum("tij,tj->ti", turn[has],
                                                        t_tails - t_pos[has])
    return Skeleton(list(template.names), template.parents.copy(), local_t,
                    Rotation.from_matrix(local_r).as_quat(), tails=tails,
                    deform=template.deform.copy())
