"""Baking a retarget into a clip: model matrices from model rotations, then local keys."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ...animation.clip import Clip, Track

__all__ = ["assemble", "to_clip", "model_scales"]


def model_scales(skeleton):
    """Each joint's scale in model space at rest: the column lengths of its rest model matrix.

    A Mixamo glTF's hips (or its Armature node) scale by 0.01, so every bone below it is
    in centimetres: a joint's own ``rest_scale`` is 1 there while its model scale is 0.01.

    Returns
    -------
    scales : (J, 3) float64
    """
    rest = skeleton.forward(skeleton.rest_local_matrices())
    return np.linalg.norm(rest[:, :3, :3], axis=-2)


def assemble(skeleton, rot, hips, hips_pos):
    """Model matrices from model rotations, rest translations and the hips' model position.

    Parameters
    ----------
    skeleton : Skeleton
    rot : (F, J, 3, 3) float64
        Model rotations (no scale).
    hips : int
    hips_pos : (F, 3) float64

    Returns
    -------
    mats : (F, J, 4, 4) float64
        Each joint's rotation times its model scale at rest (:func:`model_scales`: the
        scales inherited from its ancestors included).
    """
    n_frames, nj = rot.shape[:2]
    mats = np.zeros((n_frames, nj, 4, 4))
    mats[..., 3, 3] = 1.0
    scales = model_scales(skeleton)
    for j in range(nj):
        p = skeleton.parents[j]
        mats[:, j, :3, :3] = rot[:, j] * scales[j]
        if j == hips:
            mats[:, j, :3, 3] = hips_pos
        elif p >= 0:
            mats[:, j, :3, 3] = (mats[:, p] @ np.r_[skeleton.rest_translation[j], 1.0])[:, :3]
        else:
            mats[:, j, :3, 3] = skeleton.rest_translation[j]
    return mats


def to_clip(skeleton, mats, rot, times, name, source_clip, hips, hips_rest):
    """Local keys from model matrices: a rotation track per joint whose rotation moves, a
    translation track for the hips; when the hips hang from a non-deforming root (a
    ground-level carrier, as the bundled characters have), the root carries the horizontal
    travel, as in the bundled walks (the recorder's camera follows it)."""
    tracks = {}
    nj = len(skeleton)
    for j in range(nj):
        p = skeleton.parents[j]
        local = rot[:, j] if p < 0 else np.swapaxes(rot[:, p], -1, -2) @ rot[:, j]
        quats = Rotation.from_matrix(local).as_quat()
        # rtol=0: a turn of a fraction of a degree is motion too (allclose's default relative
        # tolerance of 1e-5 on the dot product would drop turns below 0.5 degrees)
        if np.allclose(np.abs(quats @ skeleton.rest_rotation[j]), 1.0, rtol=0.0, atol=1e-12):
            continue
        tracks[(skeleton.names[j], "rotation")] = Track("rotation", times, quats, "slerp")
    p = skeleton.parents[hips]
    world = np.c_[mats[:, hips, :3, 3], np.ones(len(times))]
    if p >= 0 and skeleton.parents[p] < 0 and not skeleton.deform[p]:
        travel = (world[:, :3] - hips_rest) * [1.0, 0.0, 1.0]
        carried = skeleton.rest_translation[p] + travel
        mats = mats.copy()
        mats[:, p, :3, 3] = carried
        tracks[(skeleton.names[p], "translation")] = Track("translation", times, carried,
                                                           "linear")
    local_t = world[:, :3] if p < 0 else np.einsum("fab,fb->fa", np.linalg.inv(mats[:, p]),
                                                   world)[:, :3]
    tracks[(skeleton.names[hips], "translation")] = Track("translation", times, local_t,
                                                          "linear")
    return Clip(name, skeleton, tracks, duration=max(source_clip.duration, times[-1]),
                loop=source_clip.loop)
