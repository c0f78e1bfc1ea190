"""Save a rig in the format its path asks for.

==========================  =========================================================
no suffix (a folder)        a rig folder (:func:`rigedit.io.rig_folder.save_rig_folder`)
``.glb`` / ``.gltf``        glTF 2.0 (:func:`rigedit.io.gltf_write.save_gltf`)
``.bvh``                    BVH: the skeleton and one clip (:func:`rigedit.io.bvh.save_bvh`)
==========================  =========================================================
"""
from __future__ import annotations

from pathlib import Path

from ..errors import RigFileError
from .load import format_function

__all__ = ["save_rig"]


def save_rig(rig, path, clips=None):
    """Write ``rig`` to ``path``; the format follows the extension.

    Parameters
    ----------
    rig : Rig
    path : str or os.PathLike
        A folder (no suffix, or an existing directory), ``.glb``, ``.gltf`` or ``.bvh``.
    clips : list[str], optional
        Names of the clips to write (all when omitted; BVH holds one, the first named or the
        rig's first clip). Only glTF and BVH take a selection; a folder gets every clip.

    Raises
    ------
    RigFileError
        For an extension rigedit does not write, a clip name the rig lacks, or more than one
        clip for a BVH file.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    for name in clips or ():
        if name not in rig.clips:
            known = ", ".join(sorted(rig.clips)) or "none"
            raise RigFileError(path, f"expected a clip of the rig ({known}), got {name!r}")
    if suffix in (".glb", ".gltf"):
        save_gltf = format_function("gltf_write", "save_gltf", path, "writer")
        return save_gltf(rig, path, clips=clips)
    if suffix == ".bvh":
        if clips is not None and len(clips) > 1:
            raise RigFileError(path, f"expected one clip for a BVH file, got {len(clips)}")
        clip = rig.clips[clips[0]] if clips else None
        return format_function("bvh", "save_bvh", path, "writer")(rig, path, clip=clip)
    if suffix == "" or path.is_dir():
        if clips is not None:
            raise RigFileError(path, "expected no clip selection for a rig folder (it holds "
                                     "every clip), got --clip")
        from .rig_folder import save_rig_folder

        return save_rig_folder(path, rig)
    raise RigFileError(path, f"expected a folder or a .glb, .gltf or .bvh file to write, got "
                             f"a {suffix} file")
