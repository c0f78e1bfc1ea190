"""FBX out: morph targets as blend shapes.

A rig's :class:`~rigedit.model.morph.MorphTargets` become one ``Deformer "BlendShape"`` on the
geometry with a ``SubDeformer "BlendShapeChannel"`` per target (its ``DeformPercent``: the
target's default weight times 100, FBX's percent, and ``FullWeights`` 100: the shape is the
whole target at full weight, no in-between shapes), and under each channel a ``Geometry
"Shape"`` with the vertices the target moves (``Indexes``), their displacements in file units
(``Vertices``, relative to the rest, as FBX shapes are) and their normal displacements
(``Normals``) where the rig has them. Weight tracks are the channels' ``DeformPercent``
curves (:mod:`rigedit.io.fbx_write_anim`).
"""
from __future__ import annotations

import numpy as np

from .fbx_document import properties70

__all__ = ["write_morphs"]


def write_morphs(scene, morphs, geometry, name, unit):
    """The blend shape deformer of ``geometry``.

    Parameters
    ----------
    scene : rigedit.io.fbx_document.Scene
    morphs : rigedit.model.morph.MorphTargets
        M targets of the geometry's V vertices.
    geometry : Int64
        The mesh geometry's id.
    name : str
        The deformer's name (the rig's).
    unit : float
        File units per metre.

    Returns
    -------
    channels : dict[str, Int64]
        Target name -> its channel's id (weight tracks are curves on it).
    """
    deformer, node = scene.add("Deformer", name, "Deformer", "BlendShape")
    node.add("Version", 100)
    scene.connect(deformer, geometry)
    channels = {}
    for m, target in enumerate(morphs.names):
        rows, deltas, normal_deltas = morphs.sparse_target(m)
        percent = float(morphs.default_weights[m]) * 100.0
        uid, channel = scene.add("Deformer", target, "SubDeformer", "BlendShapeChannel")
        channel.add("Version", 100)
        channel.add("DeformPercent", percent)
        channel.add("FullWeights", np.array([100.0]))
        channel.append(properties70(("DeformPercent", "number", percent)))
        scene.connect(uid, deformer)
        shape, s = scene.add("Geometry", target, "Geometry", "Shape")
        s.add("Version", 100)
        s.add("Indexes", np.asarray(rows, dtype=np.int32))
        s.add("Vertices", (np.asarray(deltas, dtype=np.float64) * unit).reshape(-1))
        if normal_deltas is not None:
            s.add("Normals", np.asarray(normal_deltas, dtype=np.float64).reshape(-1))
        scene.connect(shape, uid)
        channels[target] = uid
    return channels
