"""Skin weights as ``.npz``: ``indices (V, K) int32``, ``weights (V, K) float32`` and
``joints`` (the joint names the indices refer to, so a file survives joint reordering).

Reading never trusts the file's own claims: the header of each ``.npy`` member is read first
and its shape and type checked against the mesh (V rows, at most :data:`MAX_INFLUENCES`
columns) before any array is allocated.
"""
from __future__ import annotations

import zipfile
import zlib

import numpy as np

from ..errors import RigFileError
from .atomic import atomic_write
from .jsonfile import MAX_NAME_CHARS
from .paths import os_problem, regular_file

__all__ = ["load_weights", "save_weights", "weights_vertex_count", "MAX_INFLUENCES"]

#: Most influences per vertex a weights file may hold (the binding keeps up to 8).
MAX_INFLUENCES = 64
MAX_JOINTS = 2**16
#: What a broken archive or member may raise while being read (zlib.error: corrupt deflate
#: data; RuntimeError: an encrypted member).
_ZIP_ERRORS = (ValueError, OSError, EOFError, RuntimeError, NotImplementedError,
               zipfile.BadZipFile, zlib.error)


def save_weights(path, indices, weights, joint_names):
    """Write weights atomically."""
    with atomic_write(path, "wb", suffix=".npz") as fh:
        np.savez_compressed(fh, indices=np.asarray(indices, dtype=np.int32),
                            weights=np.asarray(weights, dtype=np.float32),
                            joints=np.asarray(joint_names, dtype=str))


def _header(path, zf, key):
    """``(shape, dtype)`` of member ``key`` from its .npy header, without reading the data."""
    try:
        with zf.open(f"{key}.npy") as fh:
            version = np.lib.format.read_magic(fh)
            reader = {(1, 0): np.lib.format.read_array_header_1_0,
                      (2, 0): np.lib.format.read_array_header_2_0}.get(version)
            if reader is None:
                raise ValueError(f"unsupported .npy version {version}")
            shape, fortran, dtype = reader(fh)
    except KeyError:
        return None
    except _ZIP_ERRORS as exc:
        raise RigFileError(path, f"array {key!r}: malformed .npy data ({exc})") from None
    if dtype.hasobject:
        raise RigFileError(path, f"array {key!r}: expected numbers or strings, got Python "
                                 "objects (pickled data is not read)")
    return shape, dtype


def _read(path, zf, key):
    try:
        with zf.open(f"{key}.npy") as fh:
            return np.lib.format.read_array(fh, allow_pickle=False)
    except _ZIP_ERRORS as exc:
        raise RigFileError(path, f"array {key!r}: malformed .npy data ({exc})") from None


def _open(path):
    regular_file(path)
    try:
        return zipfile.ZipFile(path)
    except zipfile.BadZipFile:
        raise RigFileError(path, "expected a weights .npz file (a zip archive), got something "
                                 "else") from None
    except OSError as exc:
        raise RigFileError(path, os_problem(exc)) from None
    except _ZIP_ERRORS as exc:
        raise RigFileError(path, f"expected a weights .npz file, got a broken zip archive "
                                 f"({exc})") from None


def _shapes(path, zf):
    found = {k: _header(path, zf, k) for k in ("indices", "weights", "joints")}
    missing = [k for k in ("indices", "weights") if found[k] is None]
    if missing:
        raise RigFileError(path, f"expected arrays 'indices' and 'weights', missing "
                                 f"{', '.join(map(repr, missing))}")
    return found


def weights_vertex_count(path):
    """Number of vertices a weights file is for (from its header, nothing else is read), or
    None when it cannot be read (then :func:`load_weights` reports the problem)."""
    try:
        with _open(path) as zf:
            shape = _shapes(path, zf)["indices"][0]
    except (RigFileError, *_ZIP_ERRORS):
        return None
    return int(shape[0]) if len(shape) >= 1 else None


def load_weights(path, skeleton, num_vertices):
    """Read weights and map them onto ``skeleton``'s joint order.

    Returns
    -------
    indices : (V, K) int32
    weights : (V, K) float64, rows normalised

    Raises
    ------
    RigFileError
        Missing or malformed file, a vertex count that differs from the mesh, joint indices
        out of range, negative or non-finite weights, a vertex without weight, duplicate or
        unknown joint names.
    """
    with _open(path) as zf:
        found = _shapes(path, zf)
        (ishape, idtype), (wshape, wdtype) = found["indices"], found["weights"]
        if len(ishape) == 2 and ishape[0] != num_vertices:
            raise RigFileError(path, f"expected weights for {num_vertices} vertices, got "
                                     f"{ishape[0]}")
        if len(ishape) != 2 or ishape != wshape:
            raise RigFileError(path, f"expected indices and weights of one shape (V, K), got "
                                     f"{ishape} and {wshape}")
        if not 1 <= ishape[1] <= MAX_INFLUENCES:
            raise RigFileError(path, f"expected 1 to {MAX_INFLUENCES} influences per vertex, "
                                     f"got {ishape[1]}")
        if idtype.kind not in "iu":
            raise RigFileError(path, f"expected integer joint indices, got {idtype}")
        if wdtype.kind != "f":
            raise RigFileError(path, f"expected floating-point weights, got {wdtype}")
        names = None
        if found["joints"] is not None:
            jshape, jdtype = found["joints"]
            if (len(jshape) != 1 or jdtype.kind not in "US" or jshape[0] > MAX_JOINTS
                    or jdtype.itemsize > 4 * MAX_NAME_CHARS):
                raise RigFileError(path, f"expected 'joints' to be a list of names, got an "
                                         f"array of {jdtype} and shape {jshape}")
            joints = _read(path, zf, "joints")
            names = [n.decode("utf-8", "replace") if isinstance(n, bytes) else str(n)
                     for n in joints.tolist()]
        indices = _read(path, zf, "indices")
        weights = _read(path, zf, "weights").astype(np.float64)
    if names is None:
        names = list(skeleton.names)
    seen = set()
    for n in names:
        if n in seen:
            raise RigFileError(path, f"expected distinct joint names, got {n!r} twice")
        seen.add(n)
    if indices.size and (indices.min() < 0 or indices.max() >= len(names)):
        bad = indices.min() if indices.min() < 0 else indices.max()
        raise RigFileError(path, f"expected joint indices in [0, {len(names) - 1}], got {bad}")
    if not np.all(np.isfinite(weights)):
        v = int(np.flatnonzero(~np.all(np.isfinite(weights), axis=1))[0])
        raise RigFileError(path, f"expected finite weights, got NaN or inf at vertex {v}")
    if np.any(weights < 0):
        v, k = np.argwhere(weights < 0)[0]
        raise RigFileError(path, f"expected weights >= 0, got {weights[v, k]:g} at vertex {v}")
    total = weights.sum(axis=1, keepdims=True)
    if not np.all(np.isfinite(total)):
        raise RigFileError(path, "expected weights of a sane size, got sums beyond float range")
    if np.any(total <= 0):
        raise RigFileError(path, f"expected a positive weight on every vertex, vertex "
                                 f"{int(np.argmax(total[:, 0] <= 0))} has none")
    used = np.unique(indices[weights > 0]) if indices.size else []
    missing_used = [names[i] for i in used if names[i] not in skeleton.index]
    if missing_used:
        raise RigFileError(path, f"weights name joints the skeleton lacks: "
                                 f"{', '.join(missing_used[:5])}")
    remap = np.array([skeleton.index.get(n, 0) for n in names], dtype=np.int32)
    return remap[indices], weights / total
