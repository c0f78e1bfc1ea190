"""Skin weights as ``.npz``: ``indices (V, K) int32``, ``weights (V, K) float32`` and
``joints`` (the joint names the indices refer to, so a file survives joint reordering)."""
from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np

from ..errors import RigFileError
from .atomic import atomic_write

__all__ = ["load_weights", "save_weights", "weights_vertex_count"]


def save_weights(path, indices, weights, joint_names):
    """Write weights atomically."""
    with atomic_write(path, "wb", suffix=".npz") as fh:
        np.savez_compressed(fh, indices=np.asarray(indices, dtype=np.int32),
                            weights=np.asarray(weights, dtype=np.float32),
                            joints=np.asarray(joint_names, dtype=str))


def weights_vertex_count(path):
    """Number of vertices a weights file is for, or None when it cannot be read (then
    :func:`load_weights` reports the problem)."""
    try:
        with np.load(path, allow_pickle=False) as data:
            return int(data["indices"].shape[0])
    except Exception:  # any unreadable file: load_weights names the problem
        return None


def load_weights(path, skeleton, num_vertices):
    """Read weights and map them onto ``skeleton``'s joint order.

    Returns
    -------
    indices : (V, K) int32
    weights : (V, K) float64, rows normalised

    Raises
    ------
    RigFileError
        Missing or malformed file, a vertex count that differs from the mesh, or joint names
        the skeleton lacks.
    """
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            indices, weights = data["indices"], data["weights"].astype(np.float64)
            names = [str(n) for n in data["joints"]] if "joints" in data else list(skeleton.names)
    except FileNotFoundError:
        raise RigFileError(path, "file not found") from None
    except KeyError as exc:
        raise RigFileError(path, f"expected arrays 'indices' and 'weights', missing {exc}") from None
    except (OSError, ValueError, zipfile.BadZipFile) as exc:
        raise RigFileError(path, f"not a weights .npz file: {exc}") from None
    if indices.ndim != 2 or indices.shape != weights.shape:
        raise RigFileError(path, f"expected indices and weights of one shape (V, K), got "
                                 f"{indices.shape} and {weights.shape}")
    if indices.shape[0] != num_vertices:
        raise RigFileError(path, f"expected weights for {num_vertices} vertices, got "
                                 f"{indices.shape[0]}")
    if indices.size and (indices.min() < 0 or indices.max() >= len(names)):
        raise RigFileError(path, f"joint index out of range for {len(names)} joints")
    missing = [n for n in names if n not in skeleton.index]
    used = np.unique(indices[weights > 0]) if indices.size else []
    missing_used = [names[i] for i in used if names[i] in missing]
    if missing_used:
        raise RigFileError(path, f"weights name joints the skeleton lacks: "
                                 f"{', '.join(missing_used[:5])}")
    remap = np.array([skeleton.index.get(n, 0) for n in names], dtype=np.int32)
    total = weights.sum(axis=1, keepdims=True)
    if np.any(total <= 0) or not np.all(np.isfinite(weights)):
        raise RigFileError(path, "expected positive, finite weights on every vertex")
    return remap[indices], weights / total
