"""FBX out: a rig's :class:`~rigedit.io.data.RigData` -> a binary FBX 7.4 file.

Written from the format's structure, without Autodesk's SDK: the container by
:mod:`rigedit.io.fbx_binary`, the document by :mod:`rigedit.io.fbx_document`, the mesh and
materials by :mod:`rigedit.io.fbx_write_mesh`, the limb nodes, skin clusters and bind pose by
:mod:`rigedit.io.fbx_write_skin`, morph targets as blend shapes by
:mod:`rigedit.io.fbx_write_morph`, the clips and weight tracks by
:mod:`rigedit.io.fbx_write_anim`.

What is written: the mesh (rest vertices, triangles, normals, UVs, one material per glTF
material used, base colour textures embedded in the file), the skeleton as limb nodes with
their rest transforms, the skin (one cluster per joint with the bind matrices), a bind pose,
morph targets as blend shape channels, and each clip as an animation stack keyed at every
frame of 30 fps and at its own keys (weight tracks as the channels' percent curves). What is
not: a clip's loop flag, a bone's tail and deform flag, a material's double-sidedness and
alpha mode, other texture maps (FBX has fields for some; rigedit keeps only the base colour).

Units: centimetres by default (``UnitScaleFactor`` 1), what Unity, Unreal and Blender import
at scale 1; metres on request (``UnitScaleFactor`` 100). Axes: the rig's own, Y up with +Z
front for a Y-up rig (rigedit's frame); a Z-up rig is declared Z up (front -Y), for the
importer to convert.
"""
from __future__ import annotations

from pathlib import Path

from ..errors import RigFileError
from .atomic import atomic_write
from .data import as_rig_data
from .fbx_binary import encode
from .fbx_document import Scene
from .fbx_write_anim import FPS, write_clips
from .fbx_write_mesh import write_mesh
from .fbx_write_morph import write_morphs
from .fbx_write_skin import write_bind_pose, write_skeleton, write_skin

__all__ = ["write_fbx", "fbx_bytes", "UNITS"]

#: ``units`` -> (file units per metre, centimetres per file unit: ``UnitScaleFactor``).
UNITS = {"cm": (100.0, 1.0), "m": (1.0, 100.0)}


def _selected(rig, clips):
    names = list(rig.clips) if clips is None else list(clips)
    for name in names:
        if name not in rig.clips:
            raise KeyError(f"expected a clip of the rig ({', '.join(rig.clips) or 'none'}), "
                           f"got {name!r}")
    return [rig.clips[name] for name in names]


def fbx_bytes(rig, clips=None, units="cm"):
    """The bytes of the FBX file of ``rig`` (a :class:`~rigedit.io.data.RigData` or a Rig).

    Parameters
    ----------
    rig : RigData or Rig
    clips : list[str], optional
        Names of the clips to write; all when None.
    units : {"cm", "m"}

    Raises
    ------
    ValueError
        For unknown ``units``, or data FBX cannot hold (a name with a NUL character, more
        than 2**31 vertices); ``KeyError`` for an unknown clip.
    """
    if units not in UNITS:
        raise ValueError(f"expected FBX units 'cm' or 'm', got {units!r}")
    rig = as_rig_data(rig)
    unit, unit_cm = UNITS[units]
    scene = Scene(up=rig.up, unit_cm=unit_cm, fps=FPS)
    chosen = _selected(rig, clips)
    joints = write_skeleton(scene, rig.skeleton, unit)
    mesh, channels = None, {}
    if len(rig.vertices):
        mesh, geometry = write_mesh(scene, rig, unit)
        if rig.indices is not None and rig.weights is not None:
            write_skin(scene, rig, geometry, joints, unit)
        morphs = rig.morphs
        if morphs is not None and morphs.count:
            channels = write_morphs(scene, morphs, geometry, rig.name, unit)
    write_bind_pose(scene, rig.name, mesh, rig.skeleton, joints, unit)
    write_clips(scene, chosen, joints, rig.skeleton, unit, channels)
    return encode(scene.nodes())


def write_fbx(data, path, clips=None, units="cm"):
    """Write ``data`` as binary FBX 7.4, atomically.

    Parameters
    ----------
    data : RigData or Rig
    path : str or Path
        A ``.fbx`` file name.
    clips : list[str], optional
        Names of the clips to write; all when None.
    units : {"cm", "m"}
        Centimetres (the default: Unity and Unreal import it at scale 1) or metres.

    Returns
    -------
    Path

    Raises
    ------
    RigFileError
        For another extension, unknown units or clip, or data FBX cannot hold (naming the
        file).
    """
    path = Path(path)
    if path.suffix.lower() != ".fbx":
        raise RigFileError(path, f"expected a .fbx file name, got {path.suffix or 'none'!r}")
    try:
        blob = fbx_bytes(data, clips=clips, units=units)
    except (KeyError, ValueError) as exc:
        raise RigFileError(path, str(exc).strip("'\"")) from None
    with atomic_write(path, "wb", suffix=".fbx") as fh:
        fh.write(blob)
    return path
