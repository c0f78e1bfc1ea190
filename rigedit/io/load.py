"""Open any rig rigedit reads, chosen by what the path is (:mod:`rigedit.io.registry`).

==========================  =========================================================
a bundled name              ``quadruped``, ``humanoid`` (:data:`rigedit.BUNDLED`)
a folder                    a rig folder (:func:`rigedit.io.rig_folder.read_rig_folder`)
``.glb`` / ``.gltf``        glTF 2.0 (:func:`rigedit.io.gltf_read.read_gltf`)
``.bvh``                    BVH motion capture (:func:`rigedit.io.bvh.read_bvh`): a
                            skeleton and one clip, no mesh
==========================  =========================================================
"""
from __future__ import annotations

from ..errors import RigFileError
from .bundled import resolve_rig_path
from .data import build_rig
from .paths import what_is
from .registry import RIG_FILE_SUFFIXES, format_of

__all__ = ["read_rig", "load_rig", "RIG_FILE_SUFFIXES", "rig_kind"]


def rig_kind(path):
    """``"folder"``, ``"gltf"`` or ``"bvh"`` for a path; ``RigFileError`` otherwise."""
    return format_of(path).name


def read_rig(rig=None, scale=None, allow_outside_uris=False):
    """Read a rig from a bundled name, a rig folder, a glTF/GLB file or a BVH file.

    Parameters
    ----------
    rig : str or os.PathLike, optional
        The default bundled character when omitted.
    scale : float, optional
        Metres per file unit for BVH files (BVH has no units; guessed from the figure's
        height when omitted). Other formats state their units, so a scale there is refused.
    allow_outside_uris : bool
        Let a glTF read buffers and images outside its folder (absolute paths, ``..``,
        ``file:``); off by default, ignored by formats without URIs.

    Returns
    -------
    RigData
        ``indices`` None when the source has no skin weights (``Rig.from_data`` computes
        them).

    Raises
    ------
    RigFileError
        When the path is of no kind rigedit reads, or the file is missing or malformed; the
        message names the file.
    """
    path = resolve_rig_path(rig)
    fmt = format_of(path)
    options = {} if scale is None else {"scale": scale}
    if set(options) - set(fmt.options):
        raise RigFileError(path, f"expected --scale/scale= only with a .bvh file (BVH has no "
                                 f"units), got it with a {fmt.name}")
    if allow_outside_uris and "allow_outside_uris" in fmt.options:   # a permission, not a need
        options["allow_outside_uris"] = True
    if fmt.suffixes and what_is(path) != "a file":
        raise RigFileError(path, f"expected a file, got {what_is(path) or 'nothing (not found)'}")
    return fmt.read(path, **options)


def load_rig(rig=None, weights_method=None, scale=None, allow_outside_uris=False):
    """Load a rig (:func:`read_rig`, then ``Rig.from_data``, which computes the weights of a
    rig folder without a weights file with ``weights_method``).

    Returns
    -------
    Rig
    """
    return build_rig(read_rig(rig, scale=scale, allow_outside_uris=allow_outside_uris),
                     weights_method=weights_method)
