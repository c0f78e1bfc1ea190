"""A per-user cache of the skinning weights computed on load, so the next load is instant.

A rig folder without ``weights.npz`` (or a file with no skin) has its weights computed when it
is loaded: seconds of bone heat for the bundled characters. The result is kept in one ``.npz``
per input under the cache folder, named by a SHA-256 of everything the result depends on:

- the mesh: its vertices (float64) and faces (int64), byte for byte;
- the skeleton: joint names, parents, rest translation, rotation and scale, bind matrices,
  tails and deform flags;
- the method and its ``max_influences``;
- the weights code itself: a hash of the source of every module of :mod:`rigedit.binding`
  (:func:`code_version`), so a change to the solver never serves old weights.

The folder is ``$RIGEDIT_CACHE_DIR`` when set (``off`` turns the cache off), else
``$XDG_CACHE_HOME/rigedit/weights`` (``~/.cache/rigedit/weights``). It is bounded: after each
store the least recently used files (by modification time, which a hit refreshes) are removed
until the folder holds at most :data:`MAX_BYTES` (500 MB, ``RIGEDIT_CACHE_MAX_MB`` overrides).

Writes go to a temporary file in the folder, then ``os.replace`` onto the name: a reader in
another process (a batch job) sees the whole old file, the whole new one or none, never a part;
two processes storing the same key write the same bytes. Anything wrong with a cache file (cut,
garbage, another key's, arrays of the wrong shape or out of range, bigger than the mesh can
need) is a miss, never an error: the weights are computed again and the file replaced. A cache
folder that cannot be written is silently skipped. Pure numpy (binding may not import io).
"""
from __future__ import annotations

import hashlib
import os
import tempfile
import zipfile
from pathlib import Path

import numpy as np

__all__ = ["cache_folder", "code_version", "weights_key", "load_weights", "store_weights",
           "evict", "MAX_BYTES", "MAX_INFLUENCES"]

#: Default bound of the cache folder's size (bytes); ``RIGEDIT_CACHE_MAX_MB`` overrides it.
MAX_BYTES = 500 * 1024 * 1024
#: The most influences per vertex a cache file may hold (compute_weights' own limit).
MAX_INFLUENCES = 8
_SUFFIX = ".npz"
_code_version = None


def cache_folder():
    """The weights cache folder (Path), or None when ``RIGEDIT_CACHE_DIR=off``."""
    chosen = os.environ.get("RIGEDIT_CACHE_DIR", "")
    if chosen.strip().lower() == "off":
        return None
    if chosen:
        return Path(chosen)
    base = os.environ.get("XDG_CACHE_HOME", "") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "rigedit" / "weights"


def max_bytes():
    """The size bound in bytes (``RIGEDIT_CACHE_MAX_MB`` or :data:`MAX_BYTES`)."""
    try:
        mb = float(os.environ["RIGEDIT_CACHE_MAX_MB"])
    except (KeyError, ValueError):
        return MAX_BYTES
    return int(mb * 1024 * 1024) if np.isfinite(mb) and mb >= 0 else MAX_BYTES


def code_version():
    """SHA-256 (hex) of the source of :mod:`rigedit.binding`'s modules, read once."""
    global _code_version
    if _code_version is None:
        h = hashlib.sha256()
        for path in sorted(Path(__file__).resolve().parent.glob("*.py")):
            h.update(path.name.encode())
            h.update(path.read_bytes())
        _code_version = h.hexdigest()
    return _code_version


def weights_key(vertices, faces, skeleton, method, max_influences=4):
    """The cache key (64 hex digits) of the weights of this mesh, skeleton and method.

    Parameters
    ----------
    vertices : (V, 3) float
    faces : (F, 3) int or None
    skeleton : Skeleton
    method : str
    max_influences : int
    """
    h = hashlib.sha256()

    def add(label, array, dtype):
        a = np.ascontiguousarray(array, dtype=dtype)
        h.update(f"{label}:{a.shape}:".encode())
        h.update(a.tobytes())

    add("vertices", vertices, np.float64)
    add("faces", np.zeros((0, 3)) if faces is None else faces, np.int64)
    sk = skeleton
    h.update("\0".join(sk.names).encode())
    add("parents", sk.parents, np.int64)
    for name in ("rest_translation", "rest_rotation", "rest_scale", "bind_matrices", "tails"):
        add(name, getattr(sk, name), np.float64)
    add("deform", sk.deform, np.bool_)
    h.update(f"method:{method}:{int(max_influences)}:code:{code_version()}".encode())
    return h.hexdigest()


def _path(folder, key):
    return folder / f"{key}{_SUFFIX}"


def load_weights(key, n_vertices, n_joints, folder=None):
    """The cached ``(indices, weights)`` of ``key``, or None on a miss.

    A hit refreshes the file's modification time (the least recently used go first). Every
    problem with the file is a miss (see the module notes).

    Returns
    -------
    indices : (V, K) int32, or None
    weights : (V, K) float64, rows summing to 1
    """
    folder = cache_folder() if folder is None else Path(folder)
    if folder is None:
        return None
    path = _path(folder, key)
    try:
        # members are stored uncompressed; a file claiming more than the mesh can need is
        # refused before anything is allocated from it
        bound = n_vertices * MAX_INFLUENCES * 8 + 4096
        with zipfile.ZipFile(path) as z:
            if any(i.file_size > bound for i in z.infolist()):
                return None
        with np.load(path, allow_pickle=False) as f:
            stored = str(f["key"])
            indices = np.asarray(f["indices"])
            weights = np.asarray(f["weights"])
    except Exception:  # absent, cut, garbage: recompute
        return None
    if not _valid(stored, key, indices, weights, n_vertices, n_joints):
        return None
    try:
        os.utime(path)
    except OSError:
        pass
    return indices.astype(np.int32, copy=False), weights.astype(np.float64, copy=False)


def _valid(stored, key, indices, weights, n_vertices, n_joints):
    """Whether a file's arrays are the weights of ``key`` for this mesh and skeleton."""
    if stored != key or indices.ndim != 2 or indices.shape != weights.shape:
        return False
    if indices.shape[0] != n_vertices or not 1 <= indices.shape[1] <= MAX_INFLUENCES:
        return False
    if indices.dtype.kind not in "iu" or weights.dtype.kind != "f":
        return False
    if indices.size and (indices.min() < 0 or indices.max() >= n_joints):
        return False
    return bool(np.all(np.isfinite(weights)) and np.all(weights >= -1e-9)
                and np.allclose(weights.sum(axis=1), 1.0, atol=1e-6))


def store_weights(key, indices, weights, folder=None):
    """Write the weights of ``key`` into the cache (atomically), then keep it in its bound.

    Returns
    -------
    Path or None
        The file written; None when the cache is off or its folder cannot be written (no
        error: the cache is an optimisation).
    """
    folder = cache_folder() if folder is None else Path(folder)
    if folder is None:
        return None
    path = _path(folder, key)
    tmp = None
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{key[:16]}-", suffix=".tmp", dir=folder)
        with os.fdopen(fd, "wb") as out:
            np.savez(out, key=np.array(key), indices=np.asarray(indices, dtype=np.int32),
                     weights=np.asarray(weights, dtype=np.float64))
        os.replace(tmp, path)
        tmp = None
    except OSError:
        return None
    finally:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass
    evict(folder, keep=path)
    return path


def evict(folder, limit=None, keep=None):
    """Remove the least recently used cache files until ``folder`` holds at most ``limit``
    bytes (:func:`max_bytes` by default); ``keep`` (the file just written) stays. Files
    another process removes meanwhile are skipped.

    Returns
    -------
    list of Path
        The files removed.
    """
    limit = max_bytes() if limit is None else int(limit)
    _remove_stale_temps(folder)
    entries = []
    for p in Path(folder).glob(f"*{_SUFFIX}"):
        try:
            st = p.stat()
        except OSError:
            continue
        entries.append((st.st_mtime, p.name, st.st_size, p))
    total = sum(e[2] for e in entries)
    removed = []
    for _, _, size, p in sorted(entries):
        if total <= limit:
            break
        if keep is not None and p == keep:
            continue
        try:
            p.unlink()
        except OSError:
            continue
        total -= size
        removed.append(p)
    return removed


def _remove_stale_temps(folder, age=3600.0):
    """Temporary files over ``age`` seconds old: left by a process killed while storing."""
    import time

    now = time.time()
    for p in Path(folder).glob(".*.tmp"):
        try:
            if now - p.stat().st_mtime > age:
                p.unlink()
        except OSError:
            pass
