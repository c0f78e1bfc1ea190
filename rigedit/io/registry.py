"""Every rig format rigedit reads and writes, in one table: what a path is -> its functions.

A reader takes a path (and the options its format has) and returns a
:class:`~rigedit.io.data.RigData`; a writer takes a ``RigData``, a path and an optional list
of clip names. A new format is one reader, one writer and one line of :data:`FORMATS`.

==========  ====================  =================================================
``folder``  a folder, no suffix   :mod:`rigedit.io.rig_folder` (mesh, skeleton, clips, weights)
``gltf``    ``.glb``, ``.gltf``   :mod:`rigedit.io.gltf_read`, :mod:`rigedit.io.gltf_write`
``bvh``     ``.bvh``              :mod:`rigedit.io.bvh`, :mod:`rigedit.io.bvh_write`: a
                                  skeleton and one clip, no mesh
``fbx``     ``.fbx``              :mod:`rigedit.io.fbx_read` (through ufbx, in a child
                                  process: :mod:`rigedit.io.fbx_isolated`),
                                  :mod:`rigedit.io.fbx_write` (binary FBX 7.4)
``rgc``     ``.rgc``              :mod:`rigedit.io.compressed_file`: a skeleton and
                                  compressed clips, no mesh
==========  ====================  =================================================
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Tuple

from ..errors import RigFileError
from .bvh import read_bvh
from .bvh_write import write_bvh
from .compressed_file import read_compressed, write_compressed
from .fbx_isolated import read_fbx  # fbx_read's reader, in a child process (see there)
from .fbx_write import write_fbx
from .gltf_read import read_gltf
from .gltf_write import save_gltf
from .paths import what_is
from .rig_folder import read_rig_folder, write_rig_folder

__all__ = ["Format", "FORMATS", "RIG_FILE_SUFFIXES", "format_of", "format_named"]


@dataclass(frozen=True)
class Format:
    """A rig format: its name, the suffixes of its files (none: a folder), its reader and
    writer, and the reading options it accepts besides the path (BVH: ``scale``)."""

    name: str
    suffixes: Tuple[str, ...]
    read: Callable
    write: Callable
    options: Tuple[str, ...] = ()


FORMATS = (
    Format("folder", (), read_rig_folder, write_rig_folder),
    Format("gltf", (".glb", ".gltf"), read_gltf, save_gltf, options=("allow_outside_uris",)),
    Format("bvh", (".bvh",), read_bvh, write_bvh, options=("scale",)),
    Format("fbx", (".fbx",), read_fbx, write_fbx),
    Format("rgc", (".rgc",), read_compressed, write_compressed),
)

#: File suffixes that hold a whole rig (besides folders and bundled names).
RIG_FILE_SUFFIXES = tuple(s for f in FORMATS for s in f.suffixes)

_FOLDER = next(f for f in FORMATS if not f.suffixes)


def format_named(name):
    """The :class:`Format` called ``name`` (``"folder"``, ``"gltf"``, ``"bvh"``)."""
    return next(f for f in FORMATS if f.name == name)


def _by_suffix(path):
    suffix = Path(path).suffix.lower()
    return next((f for f in FORMATS if suffix in f.suffixes), None)


def _expected():
    return "a rig folder or a " + ", ".join(RIG_FILE_SUFFIXES[:-1]) + \
        f" or {RIG_FILE_SUFFIXES[-1]} file"


def format_of(path, role="read"):
    """The :class:`Format` of ``path``, by its suffix, else a folder.

    Parameters
    ----------
    path : str or os.PathLike
    role : {"read", "write"}
        Reading, a path of no known suffix must be a folder or missing (reported as a
        missing folder); writing, it must have no suffix or be an existing folder.

    Raises
    ------
    RigFileError
        For a path of no kind rigedit reads (or writes).
    """
    path = Path(path)
    fmt = _by_suffix(path)
    if fmt is not None:
        return fmt
    suffix = path.suffix.lower()
    if role == "write":
        if suffix == "" or path.is_dir():
            return _FOLDER
        raise RigFileError(path, f"expected {_expected().replace('a rig folder', 'a folder')} "
                                 f"to write, got a {suffix} file")
    if what_is(path) in ("a folder", None):  # a missing path is reported as a missing folder
        return _FOLDER
    raise RigFileError(path, f"expected {_expected()}, got a {suffix or 'suffix-less'} file")
