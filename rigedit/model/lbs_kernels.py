"""The compiled linear-blend skinning kernels (numba), in the form numba compiles: imported
only by :class:`rigedit.model.skinning_kernels.Kernels`, after numba (this module imports it).

:mod:`rigedit.model.skinning` is the numpy reference and fallback. The kernels inline the
vector blends of :mod:`.skinning_simd`; numba's disk cache of a kernel is invalidated when the
kernel's own source file changes (numba's documented rule), not when a file it inlines does,
so ``SIMD_SHA256`` names the version of ``skinning_simd.py`` these kernels were last checked
against: editing that file means updating the hash here and in :mod:`.dqs_kernels` (a test
says so and gives the new value), which changes these files and so rebuilds their caches.
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange

from .skinning_simd import blend_apply4, blend_apply4_normal

__all__ = ["SIMD_SHA256", "check_groups", "lbs_py", "lbs_normals_py"]

#: sha256 of skinning_simd.py as these kernels were last compiled and checked against it.
SIMD_SHA256 = "aafe0734f8842c7eb9d9e60fbb1a4424939e4cdf825df3c1bc3ebf3630323ef1"


def _check_groups_py(indices, palette):
    """The vector blends read 16 floats per palette row and influences four at a time."""
    if palette.shape[1] != 16 or indices.shape[1] % 4 != 0:
        raise ValueError("expected palette rows of 16 floats and influences in groups of 4")


check_groups = njit(_check_groups_py)


def lbs_py(rest, indices, weights, palette, out):
    """LBS of every vertex: blend the influences' skinning matrices, apply to the rest point.

    rest (V, 3) f32; indices (V, K) i32 and weights (V, K) f32 with K a multiple of 4, each
    vertex's influences sorted by decreasing weight and padded with zero weights; palette
    (J, 16) f32, the rows of :mod:`.skinning_simd` (each 4x4 transposed); out (V, 3) f32.
    Influences go four at a time through one vector blend; a group whose first weight is zero
    is skipped (real characters have 1-2 non-zero influences on average, the bundled ones 1.9).
    The first group is blended before the loop on purpose, here and in the other two kernels:
    folded into it (zero accumulators, the loop from 0) the kernels measured 10-20% slower in
    ``benchmarks/bench_skinning.py`` (best CPU time, 10k-1M vertices).
    """
    check_groups(indices, palette)
    k_max = indices.shape[1]
    for v in prange(indices.shape[0]):
        x = rest[v, 0]
        y = rest[v, 1]
        z = rest[v, 2]
        a, b, c = blend_apply4(palette, indices[v, 0], indices[v, 1], indices[v, 2],
                                indices[v, 3], weights[v, 0], weights[v, 1], weights[v, 2],
                                weights[v, 3], x, y, z)
        for g in range(4, k_max, 4):
            if weights[v, g] == 0.0:  # sorted: the rest are zero too
                break
            a2, b2, c2 = blend_apply4(palette, indices[v, g], indices[v, g + 1],
                                       indices[v, g + 2], indices[v, g + 3], weights[v, g],
                                       weights[v, g + 1], weights[v, g + 2], weights[v, g + 3],
                                       x, y, z)
            a += a2
            b += b2
            c += c2
        out[v, 0] = a
        out[v, 1] = b
        out[v, 2] = c


def lbs_normals_py(rest, rest_normals, indices, weights, palette, out, out_normals):
    """:func:`lbs_py` plus the normals: the blended 3x3 applied to the rest normal, then
    renormalised (exact for rotations and uniform scale; the usual approximation otherwise)."""
    check_groups(indices, palette)
    k_max = indices.shape[1]
    for v in prange(indices.shape[0]):
        x = rest[v, 0]
        y = rest[v, 1]
        z = rest[v, 2]
        nx = rest_normals[v, 0]
        ny = rest_normals[v, 1]
        nz = rest_normals[v, 2]
        px, py, pz, a, b, c = blend_apply4_normal(
            palette, indices[v, 0], indices[v, 1], indices[v, 2], indices[v, 3], weights[v, 0],
            weights[v, 1], weights[v, 2], weights[v, 3], x, y, z, nx, ny, nz)
        for g in range(4, k_max, 4):
            if weights[v, g] == 0.0:
                break
            px2, py2, pz2, a2, b2, c2 = blend_apply4_normal(
                palette, indices[v, g], indices[v, g + 1], indices[v, g + 2], indices[v, g + 3],
                weights[v, g], weights[v, g + 1], weights[v, g + 2], weights[v, g + 3], x, y, z,
                nx, ny, nz)
            px += px2
            py += py2
            pz += pz2
            a += a2
            b += b2
            c += c2
        out[v, 0] = px
        out[v, 1] = py
        out[v, 2] = pz
        length = np.sqrt(a * a + b * b + c * c)
        inv = np.float32(1.0) / length if length > np.float32(0.0) else np.float32(0.0)
        out_normals[v, 0] = a * inv
        out_normals[v, 1] = b * inv
        out_normals[v, 2] = c * inv
