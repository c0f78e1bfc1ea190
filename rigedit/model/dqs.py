"""Dual-quaternion skinning (Kavan, Collins, Zara and O'Sullivan 2008), the numpy reference.

Linear blend skinning averages matrices, so two joints twisted far apart average to a matrix
that shrinks the skin between them (the "candy wrapper"); blending the joints' rigid motions as
unit dual quaternions keeps it rigid. What is supported:

- rigid joint motion (rotation and translation): blended as dual quaternions, each influence's
  quaternion flipped into the hemisphere of the vertex's strongest influence, so a vertex
  always takes the shortest way between its joints;
- scale and shear, as Kavan et al. propose (section 4.2, "two-phase" skinning): each skinning
  matrix's linear part ``A_j`` is split by polar decomposition into ``A_j = Q_j S_j`` (``Q_j`` a
  rotation, ``S_j`` symmetric: the scale/shear in bind space); the ``S_j`` are blended linearly
  and applied to the rest point first, then the rigid parts ``(Q_j, t_j)`` as dual
  quaternions. A mirroring matrix (negative determinant) keeps its reflection in ``S_j``.
  Without scale the first phase is skipped. A vertex with a single influence therefore moves
  exactly as with linear blend skinning, scaled or not.

The compiled kernel is :func:`rigedit.model.dqs_kernels.dqs_py`; this module's
:func:`dqs_skin` is its reference and fallback.
"""
from __future__ import annotations

import numpy as np

__all__ = ["palette_dual_quaternions", "dqs_skin", "matrix_to_quaternion"]


def matrix_to_quaternion(m):
    """Unit quaternions (x, y, z, w) of rotation matrices, by Shepperd's method.

    Written here rather than taken from ``scipy.spatial.transform.Rotation.from_matrix``
    because that costs 0.1-0.5 ms per call for 40 matrices (measured with SciPy 1.17), as much
    as dual-quaternion skinning 10k vertices with the compiled kernel; this is about 20 us.

    Parameters
    ----------
    m : (J, 3, 3) float
        Rotation matrices (orthonormal, determinant 1).

    Returns
    -------
    q : (J, 4) float64
    """
    m = np.asarray(m, dtype=np.float64)
    m00, m01, m02 = m[:, 0, 0], m[:, 0, 1], m[:, 0, 2]
    m10, m11, m12 = m[:, 1, 0], m[:, 1, 1], m[:, 1, 2]
    m20, m21, m22 = m[:, 2, 0], m[:, 2, 1], m[:, 2, 2]
    # Four formulas, each well conditioned when its own diagonal term is the largest:
    # 4 q_i q_k is known from the off-diagonal sums and differences for every pair.
    four = np.stack([
        [1 + m00 - m11 - m22, m01 + m10, m02 + m20, m21 - m12],
        [m01 + m10, 1 - m00 + m11 - m22, m12 + m21, m02 - m20],
        [m02 + m20, m12 + m21, 1 - m00 - m11 + m22, m10 - m01],
        [m21 - m12, m02 - m20, m10 - m01, 1 + m00 + m11 + m22],
    ])  # (4 cases, 4 components, J): row c is 4 q_c q
    j = np.arange(m.shape[0])
    case = np.argmax(np.stack([four[c, c] for c in range(4)]), axis=0)
    q = four[case, :, j]
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def palette_dual_quaternions(palette, tol=1e-6):
    """Split skinning matrices into unit dual quaternions and scale/shear matrices.

    Parameters
    ----------
    palette : (J, 4, 4) float
        Skinning matrices ``K_j = M_j · inverse_bind_j`` (affine).
    tol : float
        Largest deviation of ``A_jᵀ A_j`` from the identity still treated as rigid.

    Returns
    -------
    dq : (J, 8) float64
        Real part (x, y, z, w) then dual part (x, y, z, w) of each joint's rigid motion
        ``(Q_j, t_j)``: the dual part is ``0.5 · (t_j, 0) ⊗ q_j``.
    scale : (J, 3, 3) float64
        ``S_j`` with ``A_j = Q_j · S_j``.
    has_scale : bool
        False when every ``A_j`` is a rotation within ``tol`` (then ``S_j`` is the identity).
    """
    palette = np.asarray(palette, dtype=np.float64)
    a = palette[:, :3, :3]
    t = palette[:, :3, 3]
    gram = np.einsum("jki,jkl->jil", a, a)
    rigid = (np.abs(gram - np.eye(3)).max(initial=0.0) <= tol
             and bool(np.all(np.linalg.det(a) > 0)))
    if rigid:  # the common case, and no SVD per frame
        q_mat, scale = a, np.broadcast_to(np.eye(3), a.shape)
    else:
        u, s, vt = np.linalg.svd(a)
        # Polar decomposition from the SVD: Q = U Vt, S = V diag(s) Vt. A reflection
        # (det < 0) flips the least-stretched axis in both factors, so Q stays a rotation.
        d = np.ones_like(s)
        d[np.linalg.det(u @ vt) < 0, 2] = -1.0
        q_mat = (u * d[:, None, :]) @ vt
        scale = np.einsum("jki,jk,jkl->jil", vt, s * d, vt)
    qr = matrix_to_quaternion(q_mat)
    # dual part: 0.5 * (t, 0) ⊗ (r, w) = 0.5 * (w t + t × r, -t · r)
    qd = np.empty_like(qr)
    qd[:, :3] = 0.5 * (qr[:, 3:4] * t + np.cross(t, qr[:, :3]))
    qd[:, 3] = -0.5 * np.einsum("ji,ji->j", t, qr[:, :3])
    return np.concatenate([qr, qd], axis=1), scale, not rigid


def dqs_skin(rest, indices, weights, dq, scale=None, rest_normals=None):
    """Dual-quaternion skinning of every vertex (numpy reference).

    Parameters
    ----------
    rest : (V, 3) float
        Rest (bind-pose) vertex positions.
    indices : (V, K) int
        Joint index of each influence.
    weights : (V, K) float
        Influence weights, rows summing to 1.
    dq : (J, 8) float
        Unit dual quaternions from :func:`palette_dual_quaternions`.
    scale : (J, 3, 3) float, optional
        Scale/shear matrices, blended linearly and applied to the rest point first; None for
        rigid motion only.
    rest_normals : (V, 3) float, optional
        Unit rest normals, turned by each vertex's blended rotation (after its blended
        scale/shear, as the points) and renormalised.

    Returns
    -------
    vertices : (V, 3) float64
    normals : (V, 3) float64
        Only when ``rest_normals`` is given.
    """
    rest = np.asarray(rest, dtype=np.float64)
    weights = np.asarray(weights, dtype=np.float64)
    indices = np.asarray(indices)
    if len(rest) == 0:  # a rig without a mesh (a BVH skeleton)
        return np.zeros((0, 3)) if rest_normals is None else (np.zeros((0, 3)),) * 2
    q = np.asarray(dq, dtype=np.float64)[indices]  # (V, K, 8)
    p = rest
    n = None if rest_normals is None else np.asarray(rest_normals, dtype=np.float64)
    if scale is not None:
        blended = np.einsum("vk,vkij->vij", weights, np.asarray(scale, np.float64)[indices])
        p = np.einsum("vij,vj->vi", blended, rest)
        n = None if n is None else np.einsum("vij,vj->vi", blended, n)
    # Antipodality: q and -q are the same rotation; flip every influence into the hemisphere
    # of the strongest one so the blend takes the short way.
    pivot = q[np.arange(len(q)), np.argmax(weights, axis=1), :4]
    sign = np.where(np.einsum("vki,vi->vk", q[:, :, :4], pivot) < 0.0, -1.0, 1.0)
    b = np.einsum("vk,vki->vi", weights * sign, q)
    b /= np.linalg.norm(b[:, :4], axis=1, keepdims=True)
    r, w, d, e = b[:, :3], b[:, 3:4], b[:, 4:7], b[:, 7:8]
    # p' = p + 2 r × (r × p + w p) + 2 (w d − e r + r × d)
    moved = (p + 2.0 * np.cross(r, np.cross(r, p) + w * p)
             + 2.0 * (w * d - e * r + np.cross(r, d)))
    if n is None:
        return moved
    n = n + 2.0 * np.cross(r, np.cross(r, n) + w * n)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return moved, np.divide(n, length, out=np.zeros_like(n), where=length > 0)
