"""Spreading a bend over the joints of a spine or neck that the joint map leaves out."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from .bake import model_scales
from .calibrate import rotations_of, swing

__all__ = ["distribute_bend"]


def distribute_bend(skeleton, tgt, rot, mapped):
    """Share the bend between two mapped spine or neck joints with the unmapped joints
    between them (a source spine of 2 joints onto a target of 3), in place.

    With ``a`` and ``b`` consecutive mapped joints of the chain and ``k`` unmapped joints
    between, ``D`` is ``b``'s turn beyond its calibration relation to ``a``; the ``i``-th joint
    between takes ``D^(i/(k+1))`` (so the bend is spread and ``b`` keeps its orientation).
    Unless ``a`` is the hips (whose orientation is the whole body's), one swing at ``a`` then
    re-aims ``a -> b`` where it pointed.
    """
    cal = rotations_of(tgt.mats)
    for chain in (tgt.chains["spine"], [tgt.slots["chest"]] + tgt.chains["neck"]):
        marks = [i for i, j in enumerate(chain) if j in mapped]
        for i0, i1 in zip(marks[:-1], marks[1:]):
            a, b, run = chain[i0], chain[i1], chain[i0 + 1:i1]
            if not run:
                continue
            rigid = rot[:, a] @ (cal[a].T @ cal[b])
            delta = Rotation.from_matrix(rot[:, b] @ np.swapaxes(rigid, -1, -2)).as_rotvec()
            before = chain_vector(skeleton, rot, run + [b])
            n = len(run) + 1
            for k, j in enumerate(run, 1):
                step = Rotation.from_rotvec(delta * (k / n)).as_matrix()
                rot[:, j] = step @ rot[:, a] @ (cal[a].T @ cal[j])
            if a != tgt.slots["hips"]:
                turn = swing(chain_vector(skeleton, rot, run + [b]), before)
                for j in [a] + run:
                    rot[:, j] = turn @ rot[:, j]


def chain_vector(skeleton, rot, joints):
    """(F, 3) model vector from the parent of ``joints[0]`` to ``joints[-1]`` through each
    joint's rest offset, each turned by its parent's model rotation."""
    scales = model_scales(skeleton)
    return sum(rot[:, skeleton.parents[j]] @ (skeleton.rest_translation[j]
                                             * scales[skeleton.parents[j]])
               for j in joints)
