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

import hashlib
import os
import threading
from pathlib import Path

import numpy as np

from . import dqs_kernels
from .dqs_kernels import DQS_TASK, hemisphere_signs

__all__ = ["ready", "load", "start_loading", "disabled", "error", "Kernels", "DISABLE_ENV",
           "PARALLEL_MIN_VERTICES", "AUTO_LOAD_MIN_VERTICES", "DQS_TASK", "hemisphere_signs"]

#: A binding this big starts loading the kernels by itself (see the module's notes).
AUTO_LOAD_MIN_VERTICES = 50_000

DISABLE_ENV = "RIGEDIT_NO_NUMBA"
# Reassociation and FMA contraction let LLVM vectorise the blends; no "fast" flags that
# assume finite values or approximate divisions and square roots.
FASTMATH = {"contract", "reassoc", "nsz", "arcp"}

# Replaced before compiling (numba reads module globals): numba.prange, and the vector blends
# of skinning_simd (which imports numba, so it is imported only then).
prange = range
_blend_apply4 = _blend_apply4_normal = _check_groups = None

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


#: Below this many vertices a frame runs on one thread: waking a second one costs more than it
#: saves there, and on a busy machine a parallel call waits for its slowest thread.
PARALLEL_MIN_VERTICES = 100_000


class Kernels:
    """The compiled kernels (attributes ``lbs``, ``lbs_normals``, ``dqs`` (positions, and
    normals when given, see :mod:`.dqs_kernels`), ``rigid_dual_quaternions``) and numba
    itself.

    Call them through :meth:`run`, which picks the number of threads and serialises calls:
    numba's default "workqueue" threading layer must not run two parallel kernels at once.
    """

    def __init__(self, numba):
        global prange, _blend_apply4, _blend_apply4_normal, _check_groups
        from . import skinning_simd

        assert DQS_TASK % skinning_simd.DQ_BLOCK == 0 and skinning_simd.DQ_BLOCK == 16
        prange = dqs_kernels.prange = numba.prange
        _check_groups = numba.njit(_check_groups_py)
        _blend_apply4 = skinning_simd.blend_apply4
        _blend_apply4_normal = skinning_simd.blend_apply4_normal
        dqs_kernels._dq_blend4_into = skinning_simd.dq_blend4_into
        dqs_kernels._dq_apply16 = skinning_simd.dq_apply16
        dqs_kernels._dq_apply16_normals = skinning_simd.dq_apply16_normals
        # Inlined into the DQS kernel (numba IR), so constant flags fold away.
        helper = {"fastmath": FASTMATH, "inline": "always"}
        for name in ("_dqs_task", "_dq_blend_block", "_scale_block", "_dq_apply_one"):
            setattr(dqs_kernels, name, numba.njit(**helper)(getattr(dqs_kernels, name + "_py")))
        self.max_threads = numba.config.NUMBA_NUM_THREADS
        self._call_lock = threading.Lock()
        f32 = numba.float32[:, ::1]
        i32 = numba.int32[:, ::1]
        opts = {"parallel": True, "fastmath": FASTMATH, "cache": True, "nogil": True}
        self.numba = numba
        self.lbs = _compiled(numba, _lbs_py, [numba.void(f32, i32, f32, f32, f32)], opts)
        self.lbs_normals = _compiled(numba, _lbs_normals_py,
                                     [numba.void(f32, f32, i32, f32, f32, f32, f32)], opts)
        self.dqs = _compiled(
            numba, dqs_kernels._dqs_py,
            [numba.void(f32, f32, i32, f32, f32, f32, f32, numba.boolean, f32, f32)], opts)
        self.rigid_dual_quaternions = numba.njit(
            [numba.boolean(numba.float64[:, :, ::1], numba.float64, f32)],
            cache=True, nogil=True)(dqs_kernels._rigid_dual_quaternions_py)

    def run(self, name, n_vertices, threads, *args):
        """Run kernel ``name`` on ``args`` with ``threads`` threads (None: one below
        ``PARALLEL_MIN_VERTICES`` vertices, all of numba's above)."""
        if threads is None:
            threads = 1 if n_vertices < PARALLEL_MIN_VERTICES else self.max_threads
        with self._call_lock:
            self.numba.set_num_threads(max(1, min(int(threads), self.max_threads)))
            getattr(self, name)(*args)


def _compiled(numba, func, signatures, opts):
    """``func`` compiled for ``signatures`` only (a call with other types raises instead of
    compiling), as ``numba.njit(signatures, **opts)`` does, but from numba's disk cache only
    while the vector blocks it inlines are those the cache was built with."""
    dispatcher = numba.njit(**opts)(func)
    _flush_if_simd_changed(dispatcher)
    for signature in signatures:
        dispatcher.compile(signature)
    dispatcher.disable_compile()
    return dispatcher


def _flush_if_simd_changed(dispatcher):
    """numba keys a kernel's disk cache on a hash of the kernel's own source file, but the
    kernels inline :mod:`.skinning_simd`'s intrinsics: keep that file's hash beside the cache
    and empty the kernel's cache index when it differs, so the next compile rebuilds it
    instead of loading code built from other intrinsics."""
    cache = getattr(dispatcher, "_cache", None)
    path = getattr(cache, "cache_path", None)
    if path is None:  # caching off
        return
    from . import skinning_simd

    digest = hashlib.sha256(Path(skinning_simd.__file__).read_bytes()).hexdigest()
    func = dispatcher.py_func
    stamp = Path(path) / f"{func.__module__}.{func.__name__}.simd-sha256"
    try:
        if stamp.is_file() and stamp.read_text() == digest:
            return
        cache.flush()
        stamp.parent.mkdir(parents=True, exist_ok=True)
        stamp.write_text(digest)
    except OSError:  # a cache folder we cannot write: numba compiles without saving
        pass


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
