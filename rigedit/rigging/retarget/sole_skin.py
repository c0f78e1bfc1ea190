"""The feet on the skin: each foot's vertices, and their skinned positions and heights.

Each foot is the set of vertices its joints dominate in the skin binding (at least
:data:`DOMINANT` of their weight on the foot's joints: the ankle joint and every joint below
it), skinned on their own, and the floor is the lowest of those points in the target's
calibration pose (its rest: a rest-pose character stands on its floor, as the joint
clean-up of :mod:`.contacts` assumes).

Skinning only heights is cheap: a vertex's linear-blend position is linear in its *lifted*
vector ``z = (w_u [v, 1])_u`` over the U joints the feet use, so the heights of N vertices
in F frames are one (N, 4U) x (4U, F) matrix product (Xbot's 3,574 foot vertices over CMU
131_01's 994 frames: a few hundredths of a second; heights are kept in float32).

Pure numpy + scipy.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

__all__ = ["Soles", "has_skin", "find_soles", "palette", "skin_points", "vertex_heights",
           "sole_heights", "foot_low", "DOMINANT", "CHUNK"]

#: A vertex belongs to a foot when at least this much of its weight is on the foot's joints.
DOMINANT = 0.5
#: Frames measured at once (bounds the (frames, N) buffers of a long clip).
CHUNK = 512


@dataclass
class Soles:
    """The skinned feet of a rig.

    Attributes
    ----------
    joints : list of list of int
        Per foot, its joints (the ankle and everything below it).
    vertices : list of (N_i,) int64
        Per foot, the mesh vertices its joints dominate (never empty).
    used : (U,) int64
        The joints those vertices are weighted to (a few: the palette is computed for them
        alone).
    lifted : (sum N_i, 4 U) float64
        Each vertex's lifted vector ``(w_u x, w_u y, w_u z, w_u)`` over ``used``, foot after
        foot: its skinned position is ``sum_u K_u[:3] (w_u [v, 1])``.
    floor : float
        Model y of the lowest sole point in the calibration pose.
    size : float
        The largest extent of the first foot's vertices in that pose.
    """

    joints: list
    vertices: list
    used: np.ndarray
    lifted: np.ndarray
    floor: float = 0.0
    size: float = 1.0

    @property
    def offsets(self):
        """(n_feet + 1,) where each foot's rows start in :attr:`lifted`."""
        return np.r_[0, np.cumsum([len(v) for v in self.vertices])]


def has_skin(rig):
    """Whether ``rig`` (or None) has a skin binding with vertices."""
    binding = getattr(rig, "binding", None)
    return binding is not None and binding.num_vertices > 0


def find_soles(rig, feet, calibration_mats, what="target"):
    """The feet of ``rig`` on its skin, or None for a rig without a mesh.

    Parameters
    ----------
    rig : Rig
        Or anything with its ``skeleton`` and ``binding`` (a :class:`SkinBinding`); one
        without a binding (the editor's snapshot of a skeleton and clips) has no skin here.
    feet : list of int
        The ankle joint of each foot; the foot is its subtree.
    calibration_mats : (J, 4, 4) float64
        The standing pose the floor is measured in.
    what : str
        Names the rig in the warning below.

    Returns
    -------
    Soles or None
        None (with a warning naming the joint) also when some foot dominates no vertex:
        then the feet are kept on the floor by their joints, as the skin cannot say.
    """
    if not has_skin(rig):
        return None
    sk, binding = rig.skeleton, rig.binding
    weights = sp.csr_matrix(binding.matrix, dtype=np.float64)
    joints = [list(sk.subtree(a)) for a in feet]
    vertices = []
    for ankle, js in zip(feet, joints):
        share = np.asarray(weights[:, js].sum(axis=1)).ravel()
        v = np.flatnonzero(share >= DOMINANT)
        if len(v) == 0:
            warnings.warn(f"{what}: no vertex is mostly weighted to the foot below "
                          f"{sk.names[ankle]!r}; the feet are kept on the floor by their "
                          f"joints, not their skin", stacklevel=2)
            return None
        vertices.append(v)
    allv = np.concatenate(vertices)
    w = weights[allv]
    used = np.unique(w.indices)
    w = w[:, used].toarray()
    rest = np.c_[binding.rest_vertices[allv], np.ones(len(allv))]
    lifted = (w[:, :, None] * rest[:, None, :]).reshape(len(allv), 4 * len(used))
    soles = Soles(joints, vertices, used, lifted)
    rest_pts = skin_points(soles, sk, calibration_mats[None])[0]
    soles.floor = float(rest_pts[:, 1].min())
    soles.size = float(np.ptp(rest_pts[:len(vertices[0])], axis=0).max()) or 1.0
    return soles


def palette(soles, skeleton, mats):
    """(F, U, 4, 4) skinning matrices ``M_u . inverse_bind_u`` of the joints used."""
    return mats[:, soles.used] @ skeleton.inverse_bind_matrices[soles.used][None]


def skin_points(soles, skeleton, mats, rows=None):
    """(F, N, 3) skinned positions (linear blend) of the feet's vertices (``rows`` of them,
    all by default) in the poses ``mats`` (F, J, 4, 4)."""
    z = soles.lifted if rows is None else soles.lifted[rows]
    pal = palette(soles, skeleton, mats)[:, :, :3, :]             # (F, U, 3, 4)
    p = z @ pal.transpose(1, 3, 0, 2).reshape(z.shape[1], -1)     # (N, F x 3)
    return p.reshape(len(z), len(mats), 3).transpose(1, 0, 2)


def vertex_heights(soles, skeleton, mats):
    """(F, N) float32 model y of every foot vertex in the poses ``mats`` (F, J, 4, 4)
    (float32: a long clip's frames times thousands of vertices stay a few tens of MB, and
    a tenth of a micrometre is precise enough for a floor)."""
    pal = palette(soles, skeleton, mats)[:, :, 1, :]              # (F, U, 4)
    out = np.empty((len(mats), len(soles.lifted)), dtype=np.float32)
    for c in range(0, len(mats), CHUNK):
        out[c:c + CHUNK] = (soles.lifted @ pal[c:c + CHUNK].reshape(len(pal[c:c + CHUNK]),
                                                                      -1).T).T
    return out


def sole_heights(soles, skeleton, mats, heights=None):
    """(F, n_feet) float64 model y of each foot's lowest skinned point in each pose (from
    ``heights``, :func:`vertex_heights` of ``mats``, when given)."""
    y = vertex_heights(soles, skeleton, mats) if heights is None else heights
    off = soles.offsets
    return np.stack([y[:, a:b].min(axis=1) for a, b in zip(off[:-1], off[1:])],
                    axis=1).astype(np.float64)


def foot_low(soles, skeleton, mats, i):
    """(F,) model y of foot ``i``'s lowest skinned point in the poses ``mats`` (in float64,
    unlike :func:`sole_heights`: the pitch search compares small rises)."""
    a, b = soles.offsets[i], soles.offsets[i + 1]
    pal = palette(soles, skeleton, mats)[:, :, 1, :].reshape(len(mats), -1)
    return (soles.lifted[a:b] @ pal.T).min(axis=0)
