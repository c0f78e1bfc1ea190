"""A rig: mesh + skeleton + skin binding + clips, with the per-frame pipeline."""
from __future__ import annotations

import numpy as np

from .model.kinematics import local_to_model, skinning_matrices
from .model.pose import Pose
from .model.skinning import SkinBinding
from .binding.weights import compute_weights, default_method

__all__ = ["Rig"]


class Rig:
    """A skinned character.

    Parameters
    ----------
    skeleton : Skeleton
    vertices : (V, 3) float64
        Rest (bind-pose) positions, model space.
    faces : (F, 3) int64
    indices, weights : (V, K) arrays, optional
        Skin influences; computed with ``weights_method`` when omitted.
    clips : dict[str, Clip], optional
    name : str
    up : {"y", "z"}
        The vertical axis (bundled characters and glTF: y; the elk format: z).
    weights_method : str, optional
        How to compute missing weights: ``heat`` (the default for a mesh with faces) or
        ``idw`` (the default for a point cloud); kept as ``rig.weights_method``.
    surface : rigedit.surface.Surface, optional
        Normals, texture coordinates and materials where the source file had them (glTF);
        None otherwise. Rig folders do not store it yet.
    """

    def __init__(self, skeleton, vertices, faces, indices=None, weights=None, clips=None,
                 name="rig", up="y", weights_method=None, path=None, surface=None):
        self.skeleton = skeleton
        self.vertices = np.asarray(vertices, dtype=np.float64)
        self.faces = np.asarray(faces, dtype=np.int64)
        self.clips = dict(clips or {})
        self.name = name
        self.up = up
        self.path = path
        #: What a reader decided where its format was silent, shown by ``rigedit info``:
        #: ``{"units": ..., "frames": ...}``
        self.notes = {}
        self.surface = surface
        self.weights_computed = indices is None
        self.weights_method = weights_method or default_method(self.faces)
        if indices is None:
            indices, weights = compute_weights(self.vertices, skeleton, self.weights_method,
                                               faces=self.faces)
        self.bind(indices, weights)

    # ------------------------------------------------------------------ binding
    def bind(self, indices, weights):
        """Replace the skin influences, (V, K) each."""
        self.binding = SkinBinding(self.vertices, indices, weights, len(self.skeleton))

    @property
    def weights(self):
        """(V, J) scipy.sparse CSR matrix of skin weights, rows sum to 1."""
        return self.binding.matrix

    @property
    def num_bones(self):
        return int(np.sum(self.skeleton.parents >= 0))

    # ------------------------------------------------------------------ pipeline
    def rest_pose(self):
        """A new :class:`Pose` at the skeleton's rest."""
        return Pose(self.skeleton)

    def joint_matrices(self, pose):
        """(J, 4, 4) model-space joint matrices of ``pose``."""
        return local_to_model(self.skeleton, pose)

    def skin(self, pose, out=None, method="lbs"):
        """(V, 3) skinned vertex positions of ``pose`` (a new float64 array unless ``out``);
        ``method`` is ``"lbs"`` (linear blend) or ``"dqs"`` (dual quaternions, see
        :mod:`rigedit.model.dqs`)."""
        palette = skinning_matrices(self.skeleton, self.joint_matrices(pose))
        res = self.binding.skin(palette, method=method)
        if out is None:
            return res.astype(np.float64)
        out[:] = res
        return out

    def bounds(self):
        """(2, 3) min and max corner of the rest mesh; of the joints and bone tails at bind
        time for a rig without a mesh (a BVH skeleton). When the mesh was bound elsewhere than
        the rest pose (glTF files may store it in a frame of its own, CesiumMan's is Z up),
        the mesh skinned at the rest pose."""
        points = self.vertices
        sk = self.skeleton
        if len(points) and not np.allclose(sk.forward(sk.rest_local_matrices()),
                                           sk.bind_matrices, rtol=0, atol=1e-9):
            points = self.skin(self.rest_pose())
        if len(points) == 0:
            tails = sk.tails[np.all(np.isfinite(sk.tails), axis=1)]
            points = np.vstack([sk.bind_matrices[:, :3, 3], tails])
        return np.stack([points.min(axis=0), points.max(axis=0)])

    def posed_tails(self, model):
        """Bone tails (End Sites, leaf tails) carried by their joints' motion.

        Parameters
        ----------
        model : (J, 4, 4) float64
            Model matrices of a pose (:meth:`joint_matrices`).

        Returns
        -------
        joints : (T,) int
            The joints that have a tail.
        tails : (T, 3) float64
            Their tails in model space.
        """
        sk = self.skeleton
        joints = np.flatnonzero(np.all(np.isfinite(sk.tails), axis=1))
        local = np.einsum("tij,tj->ti", sk.inverse_bind_matrices[joints],
                          np.c_[sk.tails[joints], np.ones(len(joints))])
        return joints, np.einsum("tij,tj->ti", model[joints], local)[:, :3]

    def height(self):
        """Extent along the up axis, a scale for sizes in views and tolerances."""
        lo, hi = self.bounds()
        axis = 1 if self.up == "y" else 2
        return float(hi[axis] - lo[axis]) or float(np.linalg.norm(hi - lo)) or 1.0

    def save(self, path, clips=None):
        """Write the rig; the format follows ``path`` (a folder, .glb, .gltf or .bvh), see
        :func:`rigedit.io.save.save_rig`."""
        from .io.save import save_rig

        return save_rig(self, path, clips=clips)

    def __repr__(self):
        return (f"Rig({self.name!r}: {len(self.vertices)} vertices, {len(self.faces)} faces, "
                f"{len(self.skeleton)} joints, {len(self.clips)} clips)")
