"""A pose: local translation, rotation and scale of every joint (9 degrees of freedom each)."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from .transforms import compose_trs, euler_to_quat, normalize_quats

__all__ = ["Pose"]


class Pose:
    """Local (parent-space) transforms of every joint of a skeleton.

    Parameters
    ----------
    skeleton : Skeleton
    translation : (J, 3) float64, optional
    rotation : (J, 4) float64, optional
        Quaternions (x, y, z, w).
    scale : (J, 3) float64, optional

    Missing parts are taken from the skeleton's rest pose.
    """

    __slots__ = ("skeleton", "translation", "rotation", "scale")

    def __init__(self, skeleton, translation=None, rotation=None, scale=None):
        self.skeleton = skeleton
        self.translation = np.array(skeleton.rest_translation if translation is None
                                    else translation, dtype=np.float64)
        self.rotation = np.array(skeleton.rest_rotation if rotation is None else rotation,
                                 dtype=np.float64)
        self.scale = np.array(skeleton.rest_scale if scale is None else scale, dtype=np.float64)
        n = len(skeleton)
        for what, arr, width in (("translation", self.translation, 3),
                                 ("rotation", self.rotation, 4), ("scale", self.scale, 3)):
            if arr.shape != (n, width):
                raise ValueError(f"pose {what}: expected shape {(n, width)}, got {arr.shape}")

    # ------------------------------------------------------------------ copies, comparison
    def copy(self):
        return Pose(self.skeleton, self.translation, self.rotation, self.scale)

    def allclose(self, other, atol=1e-9):
        """True when both poses give the same local matrices (q and -q are the same rotation)."""
        dots = np.abs(np.sum(self.rotation * other.rotation, axis=1))
        return (np.allclose(self.translation, other.translation, atol=atol)
                and np.allclose(self.scale, other.scale, atol=atol)
                and np.allclose(dots, 1.0, atol=atol))

    def as_array(self):
        """(J, 10) float64: translation, rotation, scale side by side (for undo snapshots)."""
        return np.concatenate([self.translation, self.rotation, self.scale], axis=1)

    def set_array(self, arr):
        """Inverse of :meth:`as_array`."""
        arr = np.asarray(arr, dtype=np.float64)
        self.translation[:] = arr[:, :3]
        self.rotation[:] = arr[:, 3:7]
        self.scale[:] = arr[:, 7:10]

    # ------------------------------------------------------------------ per-joint edits
    def set_euler(self, joint, angles, degrees=False):
        """Set a joint's rotation relative to its rest orientation.

        Parameters
        ----------
        joint : str or int
        angles : (3,) float
            Euler angles applied X first, then Y, then Z (``Rz·Ry·Rx``), in the joint's
            rest frame: the local rotation becomes ``rest_rotation · R(angles)``.
        degrees : bool
        """
        j = self.skeleton.joint_index(joint)
        delta = Rotation.from_quat(euler_to_quat(np.asarray(angles, dtype=float), degrees))
        self.rotation[j] = (Rotation.from_quat(self.skeleton.rest_rotation[j]) * delta).as_quat()

    def get_euler(self, joint, degrees=False):
        """The rotation :meth:`set_euler` would take to give this pose, (3,) float64."""
        j = self.skeleton.joint_index(joint)
        delta = Rotation.from_quat(self.skeleton.rest_rotation[j]).inv() * Rotation.from_quat(
            self.rotation[j])
        return delta.as_euler("xyz", degrees=degrees)

    def set_rotation(self, joint, quat):
        """Set a joint's local rotation (x, y, z, w), normalised."""
        self.rotation[self.skeleton.joint_index(joint)] = normalize_quats(quat)

    def set_translation(self, joint, xyz):
        """Set a joint's local translation (parent space)."""
        self.translation[self.skeleton.joint_index(joint)] = np.asarray(xyz, dtype=float)

    def set_scale(self, joint, xyz):
        """Set a joint's local scale."""
        self.scale[self.skeleton.joint_index(joint)] = np.asarray(xyz, dtype=float)

    def reset(self, joint=None):
        """Return one joint (or all) to the rest pose."""
        sk = self.skeleton
        sl = slice(None) if joint is None else sk.joint_index(joint)
        self.translation[sl] = sk.rest_translation[sl]
        self.rotation[sl] = sk.rest_rotation[sl]
        self.scale[sl] = sk.rest_scale[sl]

    # ------------------------------------------------------------------ matrices
    def local_matrices(self):
        """(J, 4, 4) local matrices ``T · R · S``."""
        return compose_trs(self.translation, self.rotation, self.scale)

    def __repr__(self):
        return f"Pose({len(self.skeleton)} joints)"
