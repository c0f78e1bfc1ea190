"""rigedit: a rig editor for 3D characters (skeleton, skinning, posing, clips).

>>> import rigedit
>>> rig = rigedit.load_rig()            # the bundled quadruped
>>> pose = rig.rest_pose()
>>> pose.set_euler("neck_1", [0, 0, 20], degrees=True)
>>> verts = rig.skin(pose)
"""
from __future__ import annotations

from .animation import Clip, Track
from .errors import RigFileError
from .io.bundled import ASSETS_DIR, BUNDLED, resolve_rig_path
from .io.data import RigData, RigMeta
from .model import Pose, Skeleton, SkinBinding
from .rig import Rig

__all__ = ["load_rig", "save_rig", "retarget", "autorig", "compress", "resolve_rig_path", "BUNDLED",
           "ASSETS_DIR", "Rig", "RigData", "RigMeta", "Skeleton", "Pose", "Clip", "Track",
           "SkinBinding", "RigFileError"]
__version__ = "0.1.0"


def load_rig(rig=None, weights_method=None, scale=None, allow_outside_uris=False):
    """Load a rig: a bundled name (``quadruped``, the default, or ``humanoid``), a rig folder,
    a ``.glb``/``.gltf`` file or a ``.bvh`` file. The file is read into plain data
    (:func:`rigedit.io.load.read_rig`), then :meth:`Rig.from_data` builds the rig, computing
    the weights with ``weights_method`` where the source has none (a
    ``WeightsComputedWarning`` says so). ``scale``: metres per unit, BVH only.
    ``allow_outside_uris``: let a glTF read buffers and images outside its folder (off by
    default: a shared file could otherwise read any file of the machine).

    Raises
    ------
    RigFileError
        When a file is missing or malformed; the message names the file.
    """
    from .io.load import read_rig

    return Rig.from_data(read_rig(rig, scale=scale, allow_outside_uris=allow_outside_uris),
                         weights_method=weights_method)


def retarget(source_rig, source_clip, target_rig, map=None, name=None, clean_feet=True,
             progress=None):
    """Retarget a clip onto another character: two humanoids, or any two skeletons with legs
    whose joints share names or are mapped (see :func:`rigedit.rigging.retarget.pipeline`;
    ``progress(fraction, stage)`` as in :mod:`rigedit.progress`)."""
    from .rigging.retarget.pipeline import retarget as _retarget

    return _retarget(source_rig, source_clip, target_rig, map=map, name=name,
                     clean_feet=clean_feet, progress=progress)


def autorig(mesh, template="humanoid", up=None, forward=None, weights="heat", clips=True,
            progress=None, hints=None):
    """Rig a static mesh: embed a template skeleton, bind it, give it the template's clips
    (see :func:`rigedit.rigging.autorig.pipeline.autorig`; ``hints`` pins joints, {name: (x, y, z)}
    in the mesh's coordinates); ``rig.meta.autorig_report`` says what was decided (orientation,
    checks, stage times)."""
    from .rigging.autorig.pipeline import autorig as _autorig

    return _autorig(mesh, template=template, up=up, forward=forward, weights=weights,
                    clips=clips, progress=progress, hints=hints)


def save_rig(rig, path, clips=None):
    """Save a rig; the format follows the path (a folder, .glb, .gltf, .bvh). See
    :func:`rigedit.io.save.save_rig`."""
    from .io.save import save_rig as _save_rig

    return _save_rig(rig, path, clips=clips)


def compress(rig, max_error=1e-4, shell=0.03, clips=None, skin_shell=False, target="rigedit",
             progress=None):
    """Compress a rig's clips so no virtual vertex of any frame strays more than
    ``max_error`` metres (see :func:`rigedit.compression.compress_clips`).

    ``shell``: metres from each joint to its virtual vertices; ``skin_shell=True`` takes each
    joint's from the rig's skin instead (its farthest vertex; the rig must have a mesh);
    ``clips``: names (all when None; ``ValueError`` for a name the rig lacks).

    Returns
    -------
    (dict[str, CompressedClip], CompressionReport)
    """
    from .compression import compress_clips

    names = list(rig.clips) if clips is None else list(clips)
    missing = [n for n in names if n not in rig.clips]
    if missing:
        raise ValueError(f"expected clip names of the rig ({', '.join(rig.clips) or 'none'}), "
                         f"got {missing[0]!r}")
    mesh = None
    if skin_shell:
        mesh = (rig.vertices, rig.binding.indices, rig.binding.weights)
    result = compress_clips(rig.skeleton, {n: rig.clips[n] for n in names}, max_error=max_error,
                            shell=shell, mesh=mesh, target=target, progress=progress)
    return result.clips, result.report
