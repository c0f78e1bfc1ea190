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
  machine compiles; later ones load in a fraction of a second. numba rebuilds a kernel's
  cache when the kernel's own file changes; the kernels' files name the version of the
  vector blocks they inline (``SIMD_SHA256``, see :func:`cache_is_current`);
- the kernels are compiled for exact signatures (C-contiguous float32 arrays, int32 indices):
  a call with other types raises instead of compiling in the middle of a drag.

``RIGEDIT_NO_NUMBA=1`` in the environment disables the kernels (numpy only).
"""
from __future__ import annotations

import hashlib
import os
import threading
import warnings
from pathlib import Path

import numpy as np

__all__ = ["ready", "load", "start_loading", "disabled", "error", "Kernels", "DISABLE_ENV",
           "PARALLEL_MIN_VERTICES", "AUTO_LOAD_MIN_VERTICES", "DQS_TASK", "hemisphere_signs"]

#: A binding this big starts loading the kernels by itself (see the module's notes).
AUTO_LOAD_MIN_VERTICES = 50_000

DISABLE_ENV = "RIGEDIT_NO_NUMBA"
from .kernel_settings import DQS_TASK, FASTMATH  # noqa: E402  (shared with dqs_kernels)


def hemisphere_signs(dq, out):
    """out[a, b] = -1 where joints a and b's rotation quaternions (dq[:, :4]) point into
    opposite hemispheres, else 1: the DQS kernel's antipodality flips, once per frame (numpy,
    so it needs no numba).

    dq : (J, 8) float32; out : (J, J) float32
    """
    np.matmul(dq[:, :4], dq[:, :4].T, out=out)
    np.copysign(np.float32(1.0), out, out=out)
    return out


#: Below this many vertices a frame runs on one thread: waking a second one costs more than it
#: saves there, and on a busy machine a parallel call waits for its slowest thread.
PARALLEL_MIN_VERTICES = 100_000


class Kernels:
    """The compiled kernels (attributes ``lbs``, ``lbs_normals``, ``dqs`` (positions, and
    normals when given, see :mod:`.dqs_kernels`), ``rigid_dual_quaternions``) and numba
    itself.

    Call them through :meth:`run`, which picks the number of threads and serialises calls:
    numba's default "workqueue" threading layer must not run two parallel kernels at once.
    The kernels' sources (:mod:`.lbs_kernels`, :mod:`.dqs_kernels`) import numba and the
    vector blocks themselves, so building this object sets no other module's names; it is
    the one way to the kernels (:func:`load`, :func:`ready`).

    Parameters
    ----------
    numba : module
        numba, imported by the caller (:func:`load`, in the background thread).
    """

    def __init__(self, numba):
        from . import dqs_kernels, lbs_kernels, skinning_simd

        assert DQS_TASK % skinning_simd.DQ_BLOCK == 0 and skinning_simd.DQ_BLOCK == 16
        assert dqs_kernels.DQS_TASK == DQS_TASK
        self.max_threads = numba.config.NUMBA_NUM_THREADS
        self._call_lock = threading.Lock()
        f32 = numba.float32[:, ::1]
        i32 = numba.int32[:, ::1]
        # Compiled for these signatures only (a call with other types raises instead of
        # compiling in the middle of a drag); on disk only while the cache can be trusted.
        opts = {"parallel": True, "fastmath": FASTMATH, "cache": cache_is_current(),
                "nogil": True}
        self.numba = numba
        self.lbs = numba.njit([numba.void(f32, i32, f32, f32, f32)], **opts)(
            lbs_kernels.lbs_py)
        self.lbs_normals = numba.njit([numba.void(f32, f32, i32, f32, f32, f32, f32)], **opts)(
            lbs_kernels.lbs_normals_py)
        self.dqs = numba.njit(
            [numba.void(f32, f32, i32, f32, f32, f32, f32, numba.boolean, f32, f32)], **opts)(
            dqs_kernels.dqs_py)
        self.rigid_dual_quaternions = numba.njit(
            [numba.boolean(numba.float64[:, :, ::1], numba.float64, f32)],
            cache=True, nogil=True)(dqs_kernels.rigid_dual_quaternions_py)

    def run(self, name, n_vertices, threads, *args):
        """Run kernel ``name`` on ``args`` with ``threads`` threads (None: one below
        ``PARALLEL_MIN_VERTICES`` vertices, all of numba's above)."""
        if threads is None:
            threads = 1 if n_vertices < PARALLEL_MIN_VERTICES else self.max_threads
        with self._call_lock:
            self.numba.set_num_threads(max(1, min(int(threads), self.max_threads)))
            getattr(self, name)(*args)


def simd_sha256():
    """sha256 (hex) of ``skinning_simd.py`` as it is on disk (read without importing it)."""
    return hashlib.sha256((Path(__file__).parent / "skinning_simd.py").read_bytes()).hexdigest()


def cache_is_current():
    """True when the kernels' sources name the ``skinning_simd.py`` on disk (their
    ``SIMD_SHA256``), so numba's disk cache, which follows the kernels' own files only, holds
    code built from these vector blocks. Otherwise (someone edited the vector blocks and not
    the hashes) a warning, and the kernels compile without the disk cache: right, only
    slower to start. Imports the kernels' sources, so numba."""
    from . import dqs_kernels, lbs_kernels

    digest = simd_sha256()
    if lbs_kernels.SIMD_SHA256 == dqs_kernels.SIMD_SHA256 == digest:
        return True
    warnings.warn(f"skinning_simd.py changed (sha256 {digest}) but the SIMD_SHA256 of "
                  "lbs_kernels.py and dqs_kernels.py was not updated: compiling the skinning "
                  "kernels without numba's disk cache", RuntimeWarning, stacklevel=2)
    return False


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
