"""The compiled dual-quaternion skinning kernel and its per-frame helpers (numba), in the form
numba compiles: imported only by :class:`rigedit.model.skinning_kernels.Kernels`, after
numba (this module imports it and the vector blocks of :mod:`.skinning_simd`).

:mod:`rigedit.model.dqs` is the numpy reference and fallback. ``SIMD_SHA256`` is the
version of ``skinning_simd.py`` this kernel inlines, as in :mod:`.lbs_kernels` (numba's disk
cache follows this file only).
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange

from .kernel_settings import DQS_TASK, FASTMATH
from .skinning_simd import dq_apply16 as _dq_apply16
from .skinning_simd import dq_apply16_normals as _dq_apply16_normals
from .skinning_simd import dq_blend4_into as _dq_blend4_into

__all__ = ["SIMD_SHA256", "DQS_TASK", "dqs_py", "rigid_dual_quaternions_py"]

#: sha256 of skinning_simd.py as this kernel was last compiled and checked against it.
SIMD_SHA256 = "aafe0734f8842c7eb9d9e60fbb1a4424939e4cdf825df3c1bc3ebf3630323ef1"


def dqs_py(rest, rest_normals, indices, weights, dq, signs, scale, has_scale, out,
            out_normals):
    """Dual-quaternion skinning of every vertex (Kavan et al. 2008), and of its normal when
    ``out_normals`` has rows.

    rest (V, 3) f32; indices (V, K) i32 and weights (V, K) f32, K a multiple of 4, each
    vertex's influences sorted by decreasing weight and padded with zero weights; dq (J, 8)
    f32: each joint's rigid part as a unit dual quaternion, real (x, y, z, w) then dual
    (x, y, z, w); signs (J, J) f32: -1 where two joints' quaternions point into opposite
    hemispheres, else 1 (:func:`hemisphere_signs`); scale (J, 9) f32: each joint's
    scale/shear part (row-major 3x3), blended linearly and applied to the rest point (and
    normal) first when ``has_scale``; out (V, 3) f32. rest_normals and out_normals (V, 3) f32
    for normals too (each turned by the blend's rotation, after the blended scale when there
    is one, and renormalised: the approximation LBS's normals use), or both (0, 3) for none.
    Each influence's quaternion is flipped into the hemisphere of the vertex's strongest
    influence (the first).

    Two steps per block of 16 vertices (``DQ_BLOCK``): each vertex's blend of four influences
    is one 8-float vector operation (:func:`.skinning_simd.dq_blend4_into`) stored into a
    16 x 8 scratch block; then :func:`.skinning_simd.dq_apply16` transforms the 16 points at
    once, a 16-float vector per coordinate. Done per vertex in scalar code, that transform
    (50-odd operations) cost more than the blend and the memory traffic together (0.63 ms
    against 0.26 for the blend alone at 100k vertices). Each combination of scale and normals
    has a parallel loop of its own, whose task is :func:`_dqs_task_py` inlined with constant
    flags: with the scale path as a branch inside the loop, the rigid case measured 25%
    slower (0.30 -> 0.38 ms at 100k). The last n % 16 vertices are done one at a time after
    the parallel loop, for the same reason.
    """
    n = indices.shape[0]
    if (dq.shape[1] != 8 or indices.shape[1] % 4 != 0 or signs.shape[0] != dq.shape[0]
            or signs.shape[1] != dq.shape[0]):
        raise ValueError("expected dual quaternions of 8 floats, a (J, J) sign table and "
                         "influences in groups of 4")
    normals = out_normals.shape[0] > 0
    if normals and (rest_normals.shape[0] != n or out_normals.shape[0] != n):
        raise ValueError("expected rest and output normals of one row per vertex")
    whole = n - n % 16
    tasks = (whole + DQS_TASK - 1) // DQS_TASK
    if has_scale and normals:
        for task in prange(tasks):
            _dqs_task(rest, rest_normals, indices, weights, dq, signs, scale, out, out_normals,
                      task * DQS_TASK, min(whole, (task + 1) * DQS_TASK), True, True)
    elif has_scale:
        for task in prange(tasks):
            _dqs_task(rest, rest_normals, indices, weights, dq, signs, scale, out, out_normals,
                      task * DQS_TASK, min(whole, (task + 1) * DQS_TASK), True, False)
    elif normals:
        for task in prange(tasks):
            _dqs_task(rest, rest_normals, indices, weights, dq, signs, scale, out, out_normals,
                      task * DQS_TASK, min(whole, (task + 1) * DQS_TASK), False, True)
    else:
        for task in prange(tasks):
            _dqs_task(rest, rest_normals, indices, weights, dq, signs, scale, out, out_normals,
                      task * DQS_TASK, min(whole, (task + 1) * DQS_TASK), False, False)
    if whole < n:
        count = n - whole
        blend = np.empty((16, 8), np.float32)
        _dq_blend_block(indices, weights, dq, signs, whole, count, blend)
        points, turned, p0 = rest, rest_normals, whole
        if has_scale:
            points = np.empty((16, 3), np.float32)
            turned = np.empty((16, 3), np.float32)
            p0 = 0
            _scale_block(rest, rest_normals, indices, weights, scale, whole, count, points,
                         turned, normals)
        for i in range(count):
            _dq_apply_one(blend, i, points, turned, p0 + i, out, out_normals, whole + i,
                          normals)


def _dqs_task_py(rest, rest_normals, indices, weights, dq, signs, scale, out, out_normals,
                 start, stop, scaled, normals):
    """:func:`dqs_py` of the vertices start to stop (whole blocks of 16); ``scaled`` and
    ``normals`` are constants where it is inlined, so each loop compiles only its own path."""
    blend = np.empty((16, 8), np.float32)
    points = np.empty((16, 3), np.float32)
    turned = np.empty((16, 3), np.float32)
    for first in range(start, stop, 16):
        _dq_blend_block(indices, weights, dq, signs, first, 16, blend)
        if scaled:
            _scale_block(rest, rest_normals, indices, weights, scale, first, 16, points,
                         turned, normals)
            if normals:
                _dq_apply16_normals(blend, points, 0, turned, out, out_normals, first)
            else:
                _dq_apply16(blend, points, 0, out, first)
        elif normals:
            _dq_apply16_normals(blend, rest, first, rest_normals, out, out_normals, first)
        else:
            _dq_apply16(blend, rest, first, out, first)


def _dq_blend_block_py(indices, weights, dq, signs, first, count, blend):
    """blend[i] = the blend of vertex first + i's influences, for i < count."""
    for i in range(count):
        # Unsigned: numba then indexes without its negative-index wraparound (see dqs_py).
        v = np.uint64(first + i)
        # the strongest influence (the first: sorted) fixes the blend's hemisphere
        jp = indices[v, 0]
        _dq_blend4_into(dq, signs, jp, indices[v, 0], indices[v, 1], indices[v, 2],
                        indices[v, 3], weights[v, 0], weights[v, 1], weights[v, 2],
                        weights[v, 3], blend, i, False)
        for g in range(4, indices.shape[1], 4):
            if weights[v, g] == 0.0:  # sorted: the rest are zero too
                break
            _dq_blend4_into(dq, signs, jp, indices[v, g], indices[v, g + 1],
                            indices[v, g + 2], indices[v, g + 3], weights[v, g],
                            weights[v, g + 1], weights[v, g + 2], weights[v, g + 3],
                            blend, i, True)


def _scale_block_py(rest, rest_normals, indices, weights, scale, first, count, points,
                    turned, normals):
    """points[i] = (sum_k w_k S_jk) rest[first + i] for i < count, the first phase of DQS
    with scale, and the same 3x3 on rest_normals[first + i] into turned[i] when
    ``normals``."""
    for i in range(count):
        v = np.uint64(first + i)
        s0 = s1 = s2 = s3 = s4 = s5 = s6 = s7 = s8 = np.float32(0.0)
        for k in range(indices.shape[1]):
            w = weights[v, k]
            if w == 0.0:
                break
            j = indices[v, k]
            s0 += w * scale[j, 0]
            s1 += w * scale[j, 1]
            s2 += w * scale[j, 2]
            s3 += w * scale[j, 3]
            s4 += w * scale[j, 4]
            s5 += w * scale[j, 5]
            s6 += w * scale[j, 6]
            s7 += w * scale[j, 7]
            s8 += w * scale[j, 8]
        x, y, z = rest[v, 0], rest[v, 1], rest[v, 2]
        points[i, 0] = s0 * x + s1 * y + s2 * z
        points[i, 1] = s3 * x + s4 * y + s5 * z
        points[i, 2] = s6 * x + s7 * y + s8 * z
        if normals:
            x, y, z = rest_normals[v, 0], rest_normals[v, 1], rest_normals[v, 2]
            turned[i, 0] = s0 * x + s1 * y + s2 * z
            turned[i, 1] = s3 * x + s4 * y + s5 * z
            turned[i, 2] = s6 * x + s7 * y + s8 * z


def _dq_apply_one_py(blend, i, points, turned, p, out, out_normals, v, normals):
    """out[v] = points[p] moved by the blend in row i, and out_normals[v] = turned[p] turned
    by its rotation and renormalised when ``normals``: :func:`.skinning_simd.dq_apply16`'s
    formula for one vertex (the last n % 16)."""
    b0, b1, b2, b3 = blend[i, 0], blend[i, 1], blend[i, 2], blend[i, 3]
    e0, e1, e2, e3 = blend[i, 4], blend[i, 5], blend[i, 6], blend[i, 7]
    two = np.float32(2.0) / (b0 * b0 + b1 * b1 + b2 * b2 + b3 * b3)
    tx = b3 * e0 - e3 * b0 + b1 * e2 - b2 * e1
    ty = b3 * e1 - e3 * b1 + b2 * e0 - b0 * e2
    tz = b3 * e2 - e3 * b2 + b0 * e1 - b1 * e0
    for k in range(2 if normals else 1):
        src = points if k == 0 else turned
        x, y, z = src[p, 0], src[p, 1], src[p, 2]
        cx = b1 * z - b2 * y + b3 * x
        cy = b2 * x - b0 * z + b3 * y
        cz = b0 * y - b1 * x + b3 * z
        if k == 0:
            out[v, 0] = x + two * (b1 * cz - b2 * cy + tx)
            out[v, 1] = y + two * (b2 * cx - b0 * cz + ty)
            out[v, 2] = z + two * (b0 * cy - b1 * cx + tz)
        else:
            nx = x + two * (b1 * cz - b2 * cy)
            ny = y + two * (b2 * cx - b0 * cz)
            nz = z + two * (b0 * cy - b1 * cx)
            inv = np.float32(1.0) / np.sqrt(nx * nx + ny * ny + nz * nz)
            out_normals[v, 0] = nx * inv
            out_normals[v, 1] = ny * inv
            out_normals[v, 2] = nz * inv


def rigid_dual_quaternions_py(palette, tol, dq):
    """Each skinning matrix as a unit dual quaternion into ``dq`` (J, 8) f32, when every one is
    rigid: returns False (``dq`` unspecified) as soon as one's 3x3 ``A`` has ``AᵀA`` further
    than ``tol`` from the identity or a negative determinant; the caller then takes the numpy
    path of :func:`rigedit.model.dqs.palette_dual_quaternions`, which handles scale.

    palette (J, 4, 4) f64. The per-frame conversion in numpy costs 0.1-0.5 ms for 40 joints
    (tens of small array operations), as much as the kernel for 10k vertices; here about 1 us.
    """
    for j in range(palette.shape[0]):
        m = palette[j]
        for r in range(3):
            for c in range(3):
                g = m[0, r] * m[0, c] + m[1, r] * m[1, c] + m[2, r] * m[2, c]
                if abs(g - (1.0 if r == c else 0.0)) > tol:
                    return False
        det = (m[0, 0] * (m[1, 1] * m[2, 2] - m[1, 2] * m[2, 1])
               - m[0, 1] * (m[1, 0] * m[2, 2] - m[1, 2] * m[2, 0])
               + m[0, 2] * (m[1, 0] * m[2, 1] - m[1, 1] * m[2, 0]))
        if det <= 0.0:
            return False
        # Shepperd: start from the largest of 4w^2, 4x^2, 4y^2, 4z^2
        tr = m[0, 0] + m[1, 1] + m[2, 2]
        if tr >= m[0, 0] and tr >= m[1, 1] and tr >= m[2, 2]:
            qw = 1.0 + tr
            qx = m[2, 1] - m[1, 2]
            qy = m[0, 2] - m[2, 0]
            qz = m[1, 0] - m[0, 1]
        elif m[0, 0] >= m[1, 1] and m[0, 0] >= m[2, 2]:
            qw = m[2, 1] - m[1, 2]
            qx = 1.0 + m[0, 0] - m[1, 1] - m[2, 2]
            qy = m[0, 1] + m[1, 0]
            qz = m[0, 2] + m[2, 0]
        elif m[1, 1] >= m[2, 2]:
            qw = m[0, 2] - m[2, 0]
            qx = m[0, 1] + m[1, 0]
            qy = 1.0 - m[0, 0] + m[1, 1] - m[2, 2]
            qz = m[1, 2] + m[2, 1]
        else:
            qw = m[1, 0] - m[0, 1]
            qx = m[0, 2] + m[2, 0]
            qy = m[1, 2] + m[2, 1]
            qz = 1.0 - m[0, 0] - m[1, 1] + m[2, 2]
        inv = 1.0 / (qx * qx + qy * qy + qz * qz + qw * qw) ** 0.5
        qx *= inv
        qy *= inv
        qz *= inv
        qw *= inv
        tx = m[0, 3]
        ty = m[1, 3]
        tz = m[2, 3]
        dq[j, 0] = qx
        dq[j, 1] = qy
        dq[j, 2] = qz
        dq[j, 3] = qw
        # dual part 0.5 * (t, 0) ⊗ q = 0.5 * (w t + t × r, -t · r)
        dq[j, 4] = 0.5 * (qw * tx + ty * qz - tz * qy)
        dq[j, 5] = 0.5 * (qw * ty + tz * qx - tx * qz)
        dq[j, 6] = 0.5 * (qw * tz + tx * qy - ty * qx)
        dq[j, 7] = -0.5 * (tx * qx + ty * qy + tz * qz)
    return True


# Inlined into the DQS kernel (numba IR), so the constant flags of each call fold away.
_INLINE = {"fastmath": FASTMATH, "inline": "always"}
_dqs_task = njit(**_INLINE)(_dqs_task_py)
_dq_blend_block = njit(**_INLINE)(_dq_blend_block_py)
_scale_block = njit(**_INLINE)(_scale_block_py)
_dq_apply_one = njit(**_INLINE)(_dq_apply_one_py)
