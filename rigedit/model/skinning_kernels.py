"""Compiled skinning kernels (numba): linear blend and dual-quaternion skinning in one pass over
the vertices, parallel over vertex ranges, into reused float32 buffers.

The numpy code in :mod:`rigedit.model.skinning` and :mod:`rigedit.model.dqs` is the reference
(the tests compare the two) and the fallback: these kernels are used only once they are
compiled. Importing numba takes about half a second and compiling these kernels several
seconds, neither of which may show in the editor, so:

- nothing here imports numba at module import; :func:`start_loading` imports and compiles
  in a background thread, and until that is done :func:`ready` returns None and skinning runs
  in numpy. A :class:`~rigedit.model.skinning.SkinBinding` of ``AUTO_LOAD_MIN_VERTICES`` or
  more starts it at its first frame; smaller ones only use kernels someone loaded (the editor
  calls :func:`start_loading` once its window shows): the background import holds Python's
  lock much of its 1-2 s and measured to slow the foreground's work about 2x meanwhile, which
  a short command or a small mesh (numpy: about 1 ms a frame at 30k vertices) does not win
  back;
- the compiled code is cached on disk (numba's ``cache=True``): in ``__pycache__`` beside this
  file when that folder is writable (a checkout, a user install), otherwise numba's per-user
  cache folder (``~/.cache/numba``, or ``$NUMBA_CACHE_DIR``), so only the very first run on a
  machine compiles; later ones load in a fraction of a second;
- the kernels are compiled for exact signatures (C-contiguous float32 arrays, int32 indices):
  a call with other types raises instead of compiling in the middle of a drag.

``RIGEDIT_NO_NUMBA=1`` in the environment disables the kernels (numpy only).
"""
from __future__ import annotations

import os
import threading

import numpy as np

__all__ = ["ready", "load", "start_loading", "disabled", "error", "Kernels", "DISABLE_ENV",
           "PARALLEL_MIN_VERTICES", "AUTO_LOAD_MIN_VERTICES"]

#: A binding this big starts loading the kernels by itself (see the module's notes).
AUTO_LOAD_MIN_VERTICES = 50_000

DISABLE_ENV = "RIGEDIT_NO_NUMBA"
# Reassociation and FMA contraction let LLVM vectorise the blends; no "fast" flags that
# assume finite values or approximate divisions and square roots.
FASTMATH = {"contract", "reassoc", "nsz", "arcp"}

# Replaced before compiling (numba reads module globals): numba.prange, and the vector blends
# of skinning_simd (which imports numba, so it is imported only then).
prange = range
_blend_apply4 = _blend_apply4_normal = _dq_blend4_into = _dq_apply16 = _check_groups = None
_dq_blend_block = _scale_block = _dq_apply_one = _dqs_rigid_task = _dqs_scaled_task = None


def _check_groups_py(indices, palette):
    """The vector blends read 16 floats per palette row and influences four at a time."""
    if palette.shape[1] != 16 or indices.shape[1] % 4 != 0:
        raise ValueError("expected palette rows of 16 floats and influences in groups of 4")


def _lbs_py(rest, indices, weights, palette, out):
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
    _check_groups(indices, palette)
    k_max = indices.shape[1]
    for v in prange(indices.shape[0]):
        x = rest[v, 0]
        y = rest[v, 1]
        z = rest[v, 2]
        a, b, c = _blend_apply4(palette, indices[v, 0], indices[v, 1], indices[v, 2],
                                indices[v, 3], weights[v, 0], weights[v, 1], weights[v, 2],
                                weights[v, 3], x, y, z)
        for g in range(4, k_max, 4):
            if weights[v, g] == 0.0:  # sorted: the rest are zero too
                break
            a2, b2, c2 = _blend_apply4(palette, indices[v, g], indices[v, g + 1],
                                       indices[v, g + 2], indices[v, g + 3], weights[v, g],
                                       weights[v, g + 1], weights[v, g + 2], weights[v, g + 3],
                                       x, y, z)
            a += a2
            b += b2
            c += c2
        out[v, 0] = a
        out[v, 1] = b
        out[v, 2] = c


def _lbs_normals_py(rest, rest_normals, indices, weights, palette, out, out_normals):
    """:func:`_lbs_py` plus the normals: the blended 3x3 applied to the rest normal, then
    renormalised (exact for rotations and uniform scale; the usual approximation otherwise)."""
    _check_groups(indices, palette)
    k_max = indices.shape[1]
    for v in prange(indices.shape[0]):
        x = rest[v, 0]
        y = rest[v, 1]
        z = rest[v, 2]
        nx = rest_normals[v, 0]
        ny = rest_normals[v, 1]
        nz = rest_normals[v, 2]
        px, py, pz, a, b, c = _blend_apply4_normal(
            palette, indices[v, 0], indices[v, 1], indices[v, 2], indices[v, 3], weights[v, 0],
            weights[v, 1], weights[v, 2], weights[v, 3], x, y, z, nx, ny, nz)
        for g in range(4, k_max, 4):
            if weights[v, g] == 0.0:
                break
            px2, py2, pz2, a2, b2, c2 = _blend_apply4_normal(
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


#: Vertices per parallel task of the DQS kernel (a multiple of skinning_simd.DQ_BLOCK): each
#: task allocates its two small scratch blocks once.
DQS_TASK = 1024


def _dqs_py(rest, indices, weights, dq, signs, scale, has_scale, out):
    """Dual-quaternion skinning of every vertex (Kavan et al. 2008).

    dq (J, 8) f32: each joint's rigid part as a unit dual quaternion, real (x, y, z, w) then
    dual (x, y, z, w); signs (J, J) f32: -1 where two joints' quaternions point into opposite
    hemispheres, else 1 (:func:`hemisphere_signs`); scale (J, 9) f32: each joint's
    scale/shear part (row-major 3x3), blended linearly and applied to the rest point first
    when ``has_scale``. Each influence's quaternion is flipped into the hemisphere of the
    vertex's strongest influence (the first: influences sorted, padded to groups of four as
    for :func:`_lbs_py`).

    Two steps per block of 16 vertices (``DQ_BLOCK``): each vertex's blend of four influences
    is one 8-float vector operation (:func:`.skinning_simd.dq_blend4_into`) stored into a
    16 x 8 scratch block; then :func:`.skinning_simd.dq_apply16` transforms the 16 points at
    once, a 16-float vector per coordinate. Done per vertex in scalar code, that transform
    (50-odd operations) cost more than the blend and the memory traffic together (0.63 ms
    against 0.26 for the blend alone at 100k vertices). The rigid case reads the rest points
    directly; with scale the blended scale/shear is applied first into a 16 x 3 block. The
    last n % 16 vertices are transformed one at a time (:func:`_dq_apply_one_py`) after the
    parallel loop: a scalar path inside it slowed every block down.
    """
    if (dq.shape[1] != 8 or indices.shape[1] % 4 != 0 or signs.shape[0] != dq.shape[0]
            or signs.shape[1] != dq.shape[0]):
        raise ValueError("expected dual quaternions of 8 floats, a (J, J) sign table and "
                         "influences in groups of 4")
    n = indices.shape[0]
    whole = n - n % 16
    tasks = (whole + DQS_TASK - 1) // DQS_TASK
    # Two loops rather than one testing has_scale per block: with the scale path in the
    # loop, the rigid case measured 25% slower (0.30 -> 0.38 ms at 100k vertices).
    if has_scale:
        for task in prange(tasks):
            _dqs_scaled_task(rest, indices, weights, dq, signs, scale, out, task * DQS_TASK,
                             min(whole, (task + 1) * DQS_TASK))
    else:
        for task in prange(tasks):
            _dqs_rigid_task(rest, indices, weights, dq, signs, out, task * DQS_TASK,
                            min(whole, (task + 1) * DQS_TASK))
    if whole < n:
        count = n - whole
        blend = np.empty((16, 8), np.float32)
        points = rest
        p0 = whole
        if has_scale:
            points = np.empty((16, 3), np.float32)
            p0 = 0
            _scale_block(rest, indices, weights, scale, whole, count, points)
        _dq_blend_block(indices, weights, dq, signs, whole, count, blend)
        for i in range(count):
            _dq_apply_one(blend, i, points, p0 + i, out, whole + i)


def _dqs_rigid_task_py(rest, indices, weights, dq, signs, out, start, stop):
    """:func:`_dqs_py` of the vertices start to stop (whole blocks of 16), no scale."""
    blend = np.empty((16, 8), np.float32)
    for first in range(start, stop, 16):
        _dq_blend_block(indices, weights, dq, signs, first, 16, blend)
        _dq_apply16(blend, rest, first, out, first)


def _dqs_scaled_task_py(rest, indices, weights, dq, signs, scale, out, start, stop):
    """:func:`_dqs_py` of the vertices start to stop (whole blocks of 16), with scale."""
    blend = np.empty((16, 8), np.float32)
    scaled = np.empty((16, 3), np.float32)
    for first in range(start, stop, 16):
        _dq_blend_block(indices, weights, dq, signs, first, 16, blend)
        _scale_block(rest, indices, weights, scale, first, 16, scaled)
        _dq_apply16(blend, scaled, 0, out, first)


def _dq_blend_block_py(indices, weights, dq, signs, first, count, blend):
    """blend[i] = the blend of vertex first + i's influences, for i < count."""
    for i in range(count):
        # Unsigned: numba then indexes without its negative-index wraparound, which
        # measured 25% of this kernel's time (0.40 -> 0.30 ms at 100k vertices).
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


def _scale_block_py(rest, indices, weights, scale, first, count, scaled):
    """scaled[i] = (sum_k w_k S_jk) rest[first + i] for i < count: the first phase of DQS
    with scale."""
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
        scaled[i, 0] = s0 * x + s1 * y + s2 * z
        scaled[i, 1] = s3 * x + s4 * y + s5 * z
        scaled[i, 2] = s6 * x + s7 * y + s8 * z


def _dq_apply_one_py(blend, i, points, p, out, v):
    """out[v] = points[p] moved by the blend in row i: :func:`.skinning_simd.dq_apply16`'s
    formula for one vertex (the end of a task that is not a whole block)."""
    b0, b1, b2, b3 = blend[i, 0], blend[i, 1], blend[i, 2], blend[i, 3]
    e0, e1, e2, e3 = blend[i, 4], blend[i, 5], blend[i, 6], blend[i, 7]
    x, y, z = points[p, 0], points[p, 1], points[p, 2]
    two = np.float32(2.0) / (b0 * b0 + b1 * b1 + b2 * b2 + b3 * b3)
    cx = b1 * z - b2 * y + b3 * x
    cy = b2 * x - b0 * z + b3 * y
    cz = b0 * y - b1 * x + b3 * z
    tx = b3 * e0 - e3 * b0 + b1 * e2 - b2 * e1
    ty = b3 * e1 - e3 * b1 + b2 * e0 - b0 * e2
    tz = b3 * e2 - e3 * b2 + b0 * e1 - b1 * e0
    out[v, 0] = x + two * (b1 * cz - b2 * cy + tx)
    out[v, 1] = y + two * (b2 * cx - b0 * cz + ty)
    out[v, 2] = z + two * (b0 * cy - b1 * cx + tz)


#: Below this many vertices a frame runs on one thread: waking a second one costs more than it
#: saves there, and on a busy machine a parallel call waits for its slowest thread.
PARALLEL_MIN_VERTICES = 100_000


def _rigid_dual_quaternions_py(palette, tol, dq):
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


def hemisphere_signs(dq, out):
    """out[a, b] = -1 where joints a and b's rotation quaternions (dq[:, :4]) point into
    opposite hemispheres, else 1: the DQS kernel's antipodality flips, once per frame.

    dq : (J, 8) float32; out : (J, J) float32
    """
    np.matmul(dq[:, :4], dq[:, :4].T, out=out)
    np.copysign(np.float32(1.0), out, out=out)
    return out


class Kernels:
    """The compiled kernels (attributes ``lbs``, ``lbs_normals``, ``dqs``,
    ``rigid_dual_quaternions``) and numba itself.

    Call them through :meth:`run`, which picks the number of threads and serialises calls:
    numba's default "workqueue" threading layer must not run two parallel kernels at once.
    """

    def __init__(self, numba):
        global prange, _blend_apply4, _blend_apply4_normal, _dq_blend4_into, _dq_apply16
        global _check_groups, _dq_blend_block, _scale_block, _dq_apply_one, _dqs_rigid_task
        global _dqs_scaled_task
        from . import skinning_simd

        assert DQS_TASK % skinning_simd.DQ_BLOCK == 0 and skinning_simd.DQ_BLOCK == 16
        prange = numba.prange
        _check_groups = numba.njit(_check_groups_py)
        helper = {"fastmath": FASTMATH, "inline": "always"}
        _dq_blend_block = numba.njit(**helper)(_dq_blend_block_py)
        _scale_block = numba.njit(**helper)(_scale_block_py)
        _dq_apply_one = numba.njit(**helper)(_dq_apply_one_py)
        _dqs_rigid_task = numba.njit(**helper)(_dqs_rigid_task_py)
        _dqs_scaled_task = numba.njit(**helper)(_dqs_scaled_task_py)
        _blend_apply4 = skinning_simd.blend_apply4
        _blend_apply4_normal = skinning_simd.blend_apply4_normal
        _dq_blend4_into = skinning_simd.dq_blend4_into
        _dq_apply16 = skinning_simd.dq_apply16
        self.max_threads = numba.config.NUMBA_NUM_THREADS
        self._call_lock = threading.Lock()
        f32 = numba.float32[:, ::1]
        i32 = numba.int32[:, ::1]
        opts = {"parallel": True, "fastmath": FASTMATH, "cache": True, "nogil": True}
        self.numba = numba
        self.lbs = numba.njit([numba.void(f32, i32, f32, f32, f32)], **opts)(_lbs_py)
        self.lbs_normals = numba.njit([numba.void(f32, f32, i32, f32, f32, f32, f32)],
                                      **opts)(_lbs_normals_py)
        self.dqs = numba.njit([numba.void(f32, i32, f32, f32, f32, f32, numba.boolean, f32)],
                              **opts)(_dqs_py)
        self.rigid_dual_quaternions = numba.njit(
            [numba.boolean(numba.float64[:, :, ::1], numba.float64, f32)],
            cache=True, nogil=True)(_rigid_dual_quaternions_py)

    def run(self, name, n_vertices, threads, *args):
        """Run kernel ``name`` on ``args`` with ``threads`` threads (None: one below
        ``PARALLEL_MIN_VERTICES`` vertices, all of numba's above)."""
        if threads is None:
            threads = 1 if n_vertices < PARALLEL_MIN_VERTICES else self.max_threads
        with self._call_lock:
            self.numba.set_num_threads(max(1, min(int(threads), self.max_threads)))
            getattr(self, name)(*args)


_lock = threading.Lock()
_state = {"kernels": None, "tried": False, "error": None, "thread": None}


def disabled():
    """True when ``RIGEDIT_NO_NUMBA`` asks for the numpy path only."""
    return os.environ.get(DISABLE_ENV, "").strip() not in ("", "0")


def ready():
    """The compiled :class:`Kernels` if they are loaded, else None (never waits)."""
    return _state["kernels"]


def load():
    """The compiled :class:`Kernels`, importing numba and compiling (or loading the cached
    code) on the first call; None when numba is missing, disabled or fails to compile (the
    reason is in ``error()``). Blocks while another thread is loading."""
    if _state["tried"]:
        return _state["kernels"]
    with _lock:
        if not _state["tried"]:
            if disabled():
                _state["error"] = f"disabled by {DISABLE_ENV}"
            else:
                try:
                    import numba

                    _state["kernels"] = Kernels(numba)
                except Exception as exc:  # numba missing, or LLVM cannot compile here
                    _state["error"] = f"{type(exc).__name__}: {exc}"
            _state["tried"] = True
    return _state["kernels"]


def error():
    """Why the kernels are not available (None when they are, or were not tried yet)."""
    return _state["error"]


def start_loading():
    """Load the kernels in a background daemon thread (once per process); returns at once."""
    if _state["tried"] or _state["thread"] is not None or disabled():
        return
    with _lock:
        if _state["thread"] is None:
            _state["thread"] = threading.Thread(target=load, name="rigedit-kernels",
                                                daemon=True)
            _state["thread"].start()
