"""FBX out: the skeleton as limb nodes, the skin as clusters, and the bind pose.

Each joint is a ``Model`` of type ``LimbNode`` with its local rest transform (``Lcl
Translation`` in file units, ``Lcl Rotation`` as Euler XYZ degrees, ``Lcl Scaling``), a
``NodeAttribute`` ``LimbNode`` (``TypeFlags "Skeleton"``) and ``InheritType`` 1 (the parent's
whole matrix times the local one, rigedit's composition; FBX's default, 0, composes scale
differently under a non-uniform parent scale). The skin is a ``Deformer "Skin"`` on the
geometry with one ``SubDeformer "Cluster"`` per joint: the vertices it moves (``Indexes``), their
weights, ``TransformLink`` (the joint's model matrix at binding, from the skeleton's bind
matrices, which need not be its rest pose) and ``Transform`` (the mesh's matrix, the identity,
taken into the joint's bind space: the inverse bind matrix). The ``BindPose`` lists the same
matrices.
"""
from __future__ import annotations

import warnings

import numpy as np
import scipy.sparse as sp

from ..model.transforms import quat_to_euler
from .fbx_binary import Int64, Node
from .fbx_document import properties70

__all__ = ["write_skeleton", "write_skin", "write_bind_pose", "fbx_matrix", "add_model",
           "euler_degrees"]


def euler_degrees(quats):
    """(N, 4) quaternions (x, y, z, w) -> (N, 3) Euler XYZ degrees (matrix Rz·Ry·Rx, FBX's
    ``eEulerXYZ``). At gimbal lock SciPy warns and sets the third angle to zero: the triple
    is still the same rotation, so the warning is not the user's business."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "Gimbal lock", UserWarning)
        return quat_to_euler(np.asarray(quats, dtype=np.float64).reshape(-1, 4), degrees=True)


def fbx_matrix(mat, unit):
    """A (4, 4) rigedit matrix (column vectors, metres) as FBX's 16 doubles: column-major,
    the translation (elements 12-14) in file units (``unit`` per metre)."""
    m = np.array(mat, dtype=np.float64)
    m[:3, 3] *= unit
    return np.ascontiguousarray(m.T).reshape(16)


def add_model(scene, name, subtype, translation, euler, scale):
    """A new ``Model`` (``LimbNode``, ``Mesh``) at a local transform (translation in file
    units, rotation Euler XYZ degrees); returns its id."""
    uid, model = scene.add("Model", name, "Model", subtype)
    model.add("Version", 232)
    model.append(properties70(("InheritType", "enum", 1), ("DefaultAttributeIndex", "int", 0),
                              ("Lcl Translation", "lcl_t", *map(float, translation)),
                              ("Lcl Rotation", "lcl_r", *map(float, euler)),
                              ("Lcl Scaling", "lcl_s", *map(float, scale))))
    model.add("Shading", True)
    model.add("Culling", "CullingOff")
    return uid


def write_skeleton(scene, skeleton, unit):
    """A limb-node model (and its node attribute) per joint, parented as the skeleton is.

    Parameters
    ----------
    scene : rigedit.io.fbx_document.Scene
    skeleton : rigedit.model.skeleton.Skeleton
    unit : float
        File units per metre.

    Returns
    -------
    ids : list[Int64]
        The model id of each joint.
    """
    euler = euler_degrees(skeleton.rest_rotation)
    ids = []
    for j, name in enumerate(skeleton.names):
        uid = add_model(scene, name, "LimbNode", skeleton.rest_translation[j] * unit, euler[j],
                        skeleton.rest_scale[j])
        attr, node = scene.add("NodeAttribute", name, "NodeAttribute", "LimbNode")
        node.add("TypeFlags", "Skeleton")
        scene.connect(attr, uid)
        parent = skeleton.parents[j]
        scene.connect(uid, ids[parent] if parent >= 0 else Int64(0))
        ids.append(uid)
    return ids


def _columns(indices, weights, num_vertices, num_joints):
    """(J x V) CSR of the influences, rows normalised per vertex as rigedit's binding does
    (``SkinBinding``), zero weights and repeated joints merged."""
    k = indices.shape[1]
    total = weights.sum(axis=1, keepdims=True)
    w = weights / np.where(total > 0, total, 1.0)
    m = sp.csr_matrix((w.ravel(), (indices.ravel(), np.repeat(np.arange(num_vertices), k))),
                      shape=(num_joints, num_vertices))
    m.sum_duplicates()
    m.eliminate_zeros()
    m.sort_indices()
    return m


def write_skin(scene, data, geometry, joint_ids, unit):
    """The skin deformer of ``geometry`` with one cluster per joint.

    Parameters
    ----------
    scene : rigedit.io.fbx_document.Scene
    data : rigedit.io.data.RigData
        Its ``indices`` and ``weights`` (V, K) and the skeleton's bind matrices.
    geometry : Int64
        The geometry's id.
    joint_ids : list[Int64]
    unit : float
        File units per metre.
    """
    sk = data.skeleton
    skin, node = scene.add("Deformer", data.name, "Deformer", "Skin")
    node.add("Version", 101)
    node.add("Link_DeformAcuracy", 50.0)
    node.add("SkinningType", "Linear")
    scene.connect(skin, geometry)
    per_joint = _columns(np.asarray(data.indices), np.asarray(data.weights, dtype=np.float64),
                         len(data.vertices), len(sk))
    for j, name in enumerate(sk.names):
        lo, hi = per_joint.indptr[j], per_joint.indptr[j + 1]
        uid, cluster = scene.add("Deformer", name, "SubDeformer", "Cluster")
        cluster.add("Version", 100)
        cluster.add("UserData", "", "")
        cluster.add("Indexes", per_joint.indices[lo:hi].astype(np.int32))
        cluster.add("Weights", per_joint.data[lo:hi].astype(np.float64))
        cluster.add("Transform", fbx_matrix(sk.inverse_bind_matrices[j], unit))
        cluster.add("TransformLink", fbx_matrix(sk.bind_matrices[j], unit))
        scene.connect(uid, skin)
        scene.connect(joint_ids[j], uid)


def write_bind_pose(scene, name, mesh_model, skeleton, joint_ids, unit):
    """A ``BindPose`` of the mesh model (identity; None for a skeleton alone) and every
    joint at its bind matrix."""
    uid, pose = scene.add("Pose", name, "Pose", "BindPose")
    pose.add("Type", "BindPose")
    pose.add("Version", 100)
    entries = [(joint_ids[j], skeleton.bind_matrices[j]) for j in range(len(skeleton))]
    if mesh_model is not None:
        entries.insert(0, (mesh_model, np.eye(4)))
    pose.add("NbPoseNodes", len(entries))
    for node_id, mat in entries:
        entry = pose.append(Node("PoseNode"))
        entry.add("Node", node_id)
        entry.add("Matrix", fbx_matrix(mat, unit))
    return uid
