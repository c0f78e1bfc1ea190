"""Morph targets of a rig folder as ``morphs.npz``: ``names (M,)``, ``deltas (M, V, 3)
float32``, optionally ``normal_deltas (M, V, 3) float32`` and ``default_weights (M,)``.

Dense deltas, compressed: a target that moves a face's few hundred vertices is mostly zeros,
which deflate to almost nothing. Reading checks every member's header (shape and type against
the mesh's vertex count and the other members) before any array is allocated, as the weights
file does (:mod:`rigedit.io.weights_npz`).
"""
from __future__ import annotations

import numpy as np

from ..errors import RigFileError
from ..model.morph import MorphTargets
from .atomic import atomic_write
from .jsonfile import MAX_NAME_CHARS
from .weights_npz import _header, _open, _read

__all__ = ["save_morphs", "load_morphs", "MAX_TARGETS"]

#: Most targets a file may hold (faces rigs carry a few hundred at most).
MAX_TARGETS = 4096


def save_morphs(path, morphs):
    """Write ``morphs`` (:class:`~rigedit.model.morph.MorphTargets`) atomically."""
    arrays = {"names": np.asarray(list(morphs.names), dtype=str),
              "deltas": np.asarray(morphs.deltas, dtype=np.float32)}
    if morphs.normal_deltas is not None:
        arrays["normal_deltas"] = np.asarray(morphs.normal_deltas, dtype=np.float32)
    if morphs.default_weights is not None:
        arrays["default_weights"] = np.asarray(morphs.default_weights, dtype=np.float64)
    with atomic_write(path, "wb", suffix=".npz") as fh:
        np.savez_compressed(fh, **arrays)


def load_morphs(path, num_vertices):
    """Read the morph targets of a mesh of ``num_vertices`` vertices.

    Returns
    -------
    MorphTargets

    Raises
    ------
    RigFileError
        A missing or malformed file, shapes that do not fit the mesh or each other, more
        than :data:`MAX_TARGETS` targets, names that are not distinct, non-finite numbers.
    """
    with _open(path) as zf:
        found = {k: _header(path, zf, k)
                 for k in ("names", "deltas", "normal_deltas", "default_weights")}
        for key in ("names", "deltas"):
            if found[key] is None:
                raise RigFileError(path, f"expected arrays 'names' and 'deltas', missing "
                                         f"{key!r}")
        (nshape, ndtype), (dshape, ddtype) = found["names"], found["deltas"]
        if len(nshape) != 1 or ndtype.kind not in "US" or ndtype.itemsize > 4 * MAX_NAME_CHARS:
            raise RigFileError(path, f"expected 'names' to be a list of names, got an array "
                                     f"of {ndtype} and shape {nshape}")
        count = nshape[0]
        if not 1 <= count <= MAX_TARGETS:
            raise RigFileError(path, f"expected 1 to {MAX_TARGETS} targets, got {count}")
        want = (count, num_vertices, 3)
        for key in ("deltas", "normal_deltas"):
            if found[key] is not None:
                shape, dtype = found[key]
                if tuple(shape) != want or dtype.kind != "f":
                    raise RigFileError(path, f"expected {key!r} of shape {want} (targets, "
                                             f"the mesh's vertices, 3) in floats, got "
                                             f"{tuple(shape)} of {dtype}")
        if found["default_weights"] is not None:
            shape, dtype = found["default_weights"]
            if tuple(shape) != (count,) or dtype.kind != "f":
                raise RigFileError(path, f"expected 'default_weights' of shape ({count},), "
                                         f"got {tuple(shape)} of {dtype}")
        names = [str(n) for n in _read(path, zf, "names").tolist()]
        arrays = {k: _read(path, zf, k) for k in ("deltas", "normal_deltas", "default_weights")
                  if found[k] is not None}
    try:
        return MorphTargets(tuple(names), arrays["deltas"].astype(np.float32),
                            normal_deltas=None if "normal_deltas" not in arrays
                            else arrays["normal_deltas"].astype(np.float32),
                            default_weights=arrays.get("default_weights"))
    except ValueError as exc:   # names not distinct, non-finite numbers
        raise RigFileError(path, f"expected valid morph targets, got {exc}") from None
