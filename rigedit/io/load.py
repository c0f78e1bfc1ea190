"""Open any rig rigedit reads, chosen by what the path is.

==========================  =========================================================
a bundled name              ``quadruped``, ``humanoid`` (:data:`rigedit.BUNDLED`)
a folder                    a rig folder (:func:`rigedit.io.rig_folder.load_rig_folder`)
``.glb`` / ``.gltf``        glTF 2.0 (:func:`rigedit.io.gltf_read.load_gltf`)
``.bvh``                    BVH motion capture (:func:`rigedit.io.bvh.load_bvh`): a
                            skeleton and one clip, no mesh
==========================  =========================================================
"""
from __future__ import annotations

import importlib
from pathlib import Path

from ..errors import RigFileError
from .paths import what_is

__all__ = ["load_rig", "RIG_FILE_SUFFIXES", "rig_kind", "format_function"]

#: File suffixes that hold a whole rig (besides folders and bundled names).
RIG_FILE_SUFFIXES = (".glb", ".gltf", ".bvh")


def rig_kind(path):
    """``"folder"``, ``"gltf"`` or ``"bvh"`` for a path; ``RigFileError`` otherwise."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in (".glb", ".gltf"):
        return "gltf"
    if suffix == ".bvh":
        return "bvh"
    if what_is(path) in ("a folder", None):  # a missing path is reported as a missing folder
        return "folder"
    raise RigFileError(path, "expected a rig folder or a .glb, .gltf or .bvh file, got a "
                             f"{suffix or 'suffix-less'} file")


def format_function(module, function, path, role="reader"):
    """``rigedit.io.<module>.<function>``, imported lazily so that a format module that is
    missing or broken fails only for its own files, with one line naming the file."""
    try:
        return getattr(importlib.import_module(f"rigedit.io.{module}"), function)
    except (ImportError, AttributeError) as exc:
        raise RigFileError(path, f"expected a {role} for {Path(path).suffix} files "
                                 f"(rigedit.io.{module}.{function}), got none: {exc}") from exc


def load_rig(rig=None, weights_method=None, scale=None):
    """Load a rig from a bundled name, a rig folder, a glTF/GLB file or a BVH file.

    Parameters
    ----------
    rig : str or os.PathLike, optional
        The default bundled character when omitted.
    weights_method : str
        How to compute skin weights where the source has none (rig folders without a
        weights file).
    scale : float, optional
        Metres per file unit for BVH files (BVH has no units; guessed from the figure's
        height when omitted). Other formats state their units, so a scale there is refused.

    Returns
    -------
    Rig

    Raises
    ------
    RigFileError
        When the path is of no kind rigedit reads, or the file is missing or malformed; the
        message names the file.
    """
    from .. import resolve_rig_path

    path = resolve_rig_path(rig)
    kind = rig_kind(path)
    if scale is not None and kind != "bvh":
        raise RigFileError(path, f"expected --scale/scale= only with a .bvh file (BVH has no "
                                 f"units), got it with a {kind}")
    if kind != "folder" and what_is(path) != "a file":
        raise RigFileError(path, f"expected a file, got {what_is(path) or 'nothing (not found)'}")
    if kind == "bvh":
        return format_function("bvh", "load_bvh", path)(path, scale=scale)
    if kind == "gltf":
        return format_function("gltf_read", "load_gltf", path)(path)
    from .rig_folder import load_rig_folder

    return load_rig_folder(path, weights_method=weights_method)
