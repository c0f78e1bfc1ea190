"""A rig: mesh + skeleton + skin binding + clips, with the per-frame pipeline."""
from __future__ import annotations

import warnings

import numpy as np

from .io.data import RigData, RigMeta, WeightsComputedWarning, register_rig_builder
from .model.kinematics import local_to_model, skinning_matrices
from .model.pose import Pose
from .model.skinning import SkinBinding
from .binding import weights_cache
from .binding.weights import compute_weights, default_method

__all__ = ["Rig"]


class _InMeta:
    """A rig attribute that reads and writes a field of ``rig.meta``."""

    def __init__(self, field, doc):
        self.field, self.__doc__ = field, doc

    def __get__(self, rig, owner=None):
        return self if rig is None else getattr(rig.meta, self.field)

    def __set__(self, rig, value):
        setattr(rig.meta, self.field, value)


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
    meta : rigedit.io.data.RigMeta, optional
        Where the rig came from and what its reader decided (units, rotation orders, clip
        files, notes); kept as ``rig.meta``. A new, empty one when omitted.
    morphs : rigedit.model.morph.MorphTargets, optional
        Morph targets of ``vertices`` (``rig.morphs``), applied by the binding before
        skinning with the weights of ``binding.set_morph_weights`` (:meth:`skin` takes them
        per call).
    """

    def __init__(self, skeleton, vertices, faces, indices=None, weights=None, clips=None,
                 name="rig", up="y", weights_method=None, path=None, surface=None, meta=None,
                 morphs=None):
        self.skeleton = skeleton
        self.vertices = np.asarray(vertices, dtype=np.float64)
        self.faces = np.asarray(faces, dtype=np.int64)
        self.clips = dict(clips or {})
        self.name = name
        self.up = up
        self.path = path
        self.meta = RigMeta(source=path) if meta is None else meta
        self.surface = surface
        self.morphs = morphs
        self.weights_computed = indices is None
        self.weights_method = weights_method or default_method(self.faces)
        if indices is None:
            indices, weights = compute_weights(self.vertices, skeleton, self.weights_method,
                                               faces=self.faces)
        self.bind(indices, weights)

    @classmethod
    def from_data(cls, data, weights_method=None):
        """The rig of a reader's :class:`~rigedit.io.data.RigData`.

        Where the data has no skin influences (a rig folder without a weights file) the
        weights are computed here, with ``weights_method`` (``heat`` by default for a mesh
        with faces, ``idw`` for a point cloud, see :func:`rigedit.binding.weights.
        default_method`), which can take seconds: a :class:`WeightsComputedWarning` says so
        and ``rig.weights_computed`` is True.
        """
        indices, weights = data.indices, data.weights
        method = weights_method or default_method(data.faces)
        if indices is None:
            what = "no weights file" if data.meta.format == "folder" else "no skin weights"
            # the weights of an earlier load of the same mesh, skeleton and method, if cached
            key = weights_cache.weights_key(data.vertices, data.faces, data.skeleton, method)
            cached = weights_cache.load_weights(key, len(data.vertices), len(data.skeleton))
            how = f"computed weights ({method})" if cached is None else \
                f"weights ({method}) from the cache of an earlier load"
            warnings.warn(f"{data.meta.source}: {what}; {how}",
                          WeightsComputedWarning, stacklevel=3)
            if cached is None:
                indices, weights = compute_weights(data.vertices, data.skeleton, method,
                                                   faces=data.faces)
                weights_cache.store_weights(key, indices, weights)
            else:
                indices, weights = cached
        rig = cls(data.skeleton, data.vertices, data.faces, indices, weights, data.clips,
                  name=data.name, up=data.up, weights_method=method, path=data.meta.source,
                  surface=data.surface, meta=data.meta, morphs=data.morphs)
        rig.weights_computed = data.indices is None
        return rig

    def data(self):
        """The rig as a :class:`~rigedit.io.data.RigData` for the writers: the same arrays,
        clips and ``meta`` (not copies), the influences as bound (``binding.indices``,
        ``binding.weights``: (V, K), rows summing to 1)."""
        return RigData(self.skeleton, self.vertices, self.faces, self.binding.indices,
                       self.binding.weights, self.clips, surface=self.surface, name=self.name,
                       up=self.up, meta=self.meta, morphs=self.morphs)

    # the older spellings of three fields of ``meta`` (rig attributes before ``meta`` existed)
    notes = _InMeta("notes", "What a reader decided where its format was silent "
                    "(``meta.notes``), shown by ``rigedit info``: ``{\"units\": ..., ...}``.")
    source_rotation_orders = _InMeta("rotation_orders", "Joint name -> rotation order of the "
                                     "BVH file read (``meta.rotation_orders``).")
    autorig_report = _InMeta("autorig_report", "What :func:`rigedit.autorig` decided "
                             "(``meta.autorig_report``), None otherwise.")

    # ------------------------------------------------------------------ binding
    def bind(self, indices, weights):
        """Replace the skin influences, (V, K) each (the morph weights in effect are kept)."""
        old = getattr(self, "binding", None)
        self.binding = SkinBinding(self.vertices, indices, weights, len(self.skeleton),
                                   morphs=self.morphs)
        if old is not None and self.morphs is not None and old.morphs is self.morphs:
            self.binding.set_morph_weights(old.morph_weights)

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

    def skin(self, pose, out=None, method="lbs", morph_weights=None):
        """(V, 3) skinned vertex positions of ``pose`` (a new float64 array unless ``out``);
        ``method`` is ``"lbs"`` (linear blend) or ``"dqs"`` (dual quaternions, see
        :mod:`rigedit.model.dqs`).

        ``morph_weights`` (None: the targets' default weights; (M,) numbers or ``{name:
        weight}``, a clip's :meth:`~rigedit.animation.clip.Clip.sample_morphs`) morph the rest
        before skinning, for this call only: the binding's weights (the editor's) are put
        back after."""
        palette = skinning_matrices(self.skeleton, self.joint_matrices(pose))
        before = self.binding.morph_weights
        self.binding.set_morph_weights(morph_weights)
        try:
            res = self.binding.skin(palette, method=method)
            if out is None:
                return res.astype(np.float64)
            out[:] = res
            return out
        finally:
            self.binding.set_morph_weights(before)

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
        """Write the rig; the format follows ``path`` (a folder, .glb, .gltf, .fbx or .bvh), see
        :func:`rigedit.io.save.save_rig`."""
        # imported here, not at the top: the registry loads every format's modules (glTF's
        # pygltflib among them), about 0.1 s that ``import rigedit`` need not pay
        from .io.save import save_rig

        return save_rig(self.data(), path, clips=clips)

    def __repr__(self):
        return (f"Rig({self.name!r}: {len(self.vertices)} vertices, {len(self.faces)} faces, "
                f"{len(self.skeleton)} joints, {len(self.clips)} clips)")


# the Rig-returning readers kept in io for compatibility build through this (rigedit/io/data.py)
register_rig_builder(Rig.from_data)
