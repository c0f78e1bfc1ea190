"""Save a rig in the format its path asks for (:mod:`rigedit.io.registry`).

==========================  =========================================================
no suffix (a folder)        a rig folder (:func:`rigedit.io.rig_folder.save_rig_folder`)
``.glb`` / ``.gltf``        glTF 2.0 (:func:`rigedit.io.gltf_write.save_gltf`)
``.fbx``                    binary FBX 7.4 in centimetres (:func:`rigedit.io.fbx_write.write_fbx`)
``.bvh``                    BVH: the skeleton and one clip (:func:`rigedit.io.bvh.save_bvh`)
==========================  =========================================================
"""
from __future__ import annotations

from pathlib import Path

from ..errors import RigFileError
from .data import as_rig_data
from .registry import format_of

__all__ = ["save_rig"]


def save_rig(rig, path, clips=None):
    """Write ``rig`` to ``path``; the format follows the extension.

    Parameters
    ----------
    rig : RigData or Rig
        The rig's data (:class:`~rigedit.io.data.RigData`; a Rig gives its ``data()``).
    path : str or os.PathLike
        A folder (no suffix, or an existing directory), ``.glb``, ``.gltf``, ``.fbx`` or
        ``.bvh``.
    clips : list[str], optional
        Names of the clips to write (all when omitted; BVH holds one, the first named or the
        rig's first clip). Only glTF, FBX and BVH take a selection; a folder gets every clip.

    Raises
    ------
    RigFileError
        For an extension rigedit does not write, a clip name the rig lacks, or more than one
        clip for a BVH file.
    """
    path = Path(path)
    data = as_rig_data(rig)
    for name in clips or ():
        if name not in data.clips:
            known = ", ".join(sorted(data.clips)) or "none"
            raise RigFileError(path, f"expected a clip of the rig ({known}), got {name!r}")
    return format_of(path, role="write").write(data, path, clips=clips)
