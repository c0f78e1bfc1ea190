"""Open and save: the document's rig read from and written to files.

Reading and writing go through the package's stable entry points, :func:`rigedit.load_rig` and
:func:`rigedit.save_rig` (a bundled name, a rig folder, glTF, BVH), so the editor does not
depend on how io is built inside. A file that cannot be read raises
:class:`~rigedit.errors.RigFileError` (a ``ValueError``) and leaves the document as it was.

The File menu's other files are here too, so the window reaches io only through the editor:
the readers the window runs in a worker (:func:`load_rig`, :func:`load_rig_folder`,
:func:`load_mesh_skeleton`; they return a rig for ``Document.set_rig``), and the writers and
the weights file (:func:`export_pose`, :func:`export_skeleton`, :func:`save_weights`,
:func:`load_weights`, one undo step).
"""
from __future__ import annotations

import warnings
from pathlib import Path

from ..io import weights_npz
from ..io.atomic import write_json
from ..io.bundled import is_bundled
from ..io.mesh import load_mesh
from ..io.rig_folder import read_rig_folder
from ..io.skeleton_json import load_skeleton, save_skeleton
from ..rig import Rig
from .compression import shown_clips   # compressed clips open read-only
from .recompute import compute_weights_for

__all__ = ["open_document", "open_rig", "save_rig_folder", "export_rig", "load_rig",
           "load_rig_folder", "load_mesh_skeleton", "is_bundled", "pose_to_dict",
           "export_pose", "export_skeleton", "load_weights", "save_weights"]


# ---------------------------------------------------------------------- reading a rig
def load_rig(path=None, quiet=False, **options):
    """:func:`rigedit.load_rig` of ``path`` (the default character when None).

    ``quiet`` silences the reader's warnings (a BVH's unit guess, weights computed): the
    window shows what the reader decided from ``rig.notes`` instead.
    """
    from .. import load_rig as _load_rig

    if not quiet:
        return shown_clips(_load_rig(path, **options))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return shown_clips(_load_rig(path, **options))


def load_rig_folder(path):
    """The rig of the rig folder ``path`` (a mesh, ``skeleton.json``, optional weights and
    animations); weights computed where the folder has none, without a warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "weights computed" is expected, not an error
        return shown_clips(Rig.from_data(read_rig_folder(path)))


def load_mesh_skeleton(mesh_path, skeleton_path, progress=None):
    """A rig of a mesh file and a skeleton JSON file; its weights are computed.

    Parameters
    ----------
    mesh_path, skeleton_path : str or Path
    progress : callable, optional
        ``progress(fraction, stage=None)`` (:mod:`rigedit.progress`): None at the start
        (reading: cannot tell), then the weights' fractions; its ``Cancelled`` stops the work.

    Returns
    -------
    Rig
        Named after the mesh file, with the skeleton file's up axis.
    """
    if progress is not None:
        progress(None)
    skeleton, meta = load_skeleton(skeleton_path)
    vertices, faces = load_mesh(mesh_path)
    indices, weights = compute_weights_for(vertices, skeleton, progress=progress, faces=faces)
    return Rig(skeleton, vertices, faces, indices, weights, name=Path(mesh_path).stem,
               up=meta["up"])


def open_document(path=None, **options):
    """A new :class:`~rigedit.editor.document.Document` on the rig at ``path`` (the default
    character when None); ``options`` go to :func:`rigedit.load_rig`."""
    from .document import Document

    return Document(load_rig(path, **options))


def open_rig(document, path=None, **options):
    """Open the rig at ``path`` in ``document`` (history cleared; RigReplaced); returns it.

    Reading may take seconds (weights computed for a mesh without them): the window runs
    :func:`rigedit.load_rig` in a worker and hands the rig to ``Document.set_rig``.
    """
    rig = load_rig(path, **options)
    document.set_rig(rig)
    return rig


def save_rig_folder(document, path=None):
    """Write the rig folder to ``path`` (default: the folder it came from, ``rig.path``);
    the document then has no unsaved changes and remembers the folder.

    Returns
    -------
    Path
        The folder written.

    Raises
    ------
    ValueError
        Without a folder to write, for a bundled character's own folder (read-only) when no
        path is given, or for a path with a file suffix (see :func:`export_rig`).
    """
    from .. import ASSETS_DIR, save_rig

    rig = document.rig
    if path is None:
        path = rig.path
        if path is None:
            raise ValueError(f"{rig.name} has no folder yet: give one to save it into")
        if Path(ASSETS_DIR).resolve() in (Path(path).resolve(), *Path(path).resolve().parents):
            raise ValueError(f"{rig.name} is a bundled character (read-only): give a folder "
                             "to save it into")
    path = Path(path)
    if path.suffix and not path.is_dir():
        raise ValueError(f"expected a folder to save {rig.name} into, got the file {path} "
                         "(export writes files)")
    save_rig(rig, path)
    rig.path = path
    document.mark_saved()
    return path


def export_rig(document, path, clips=None):
    """Write the rig as ``.glb``/``.gltf`` (every clip, or ``clips``) or ``.bvh`` (the
    skeleton and the current clip); unlike a save, the document keeps its unsaved state."""
    from .. import save_rig

    if clips is None and Path(path).suffix.lower() == ".bvh" and document.current_clip:
        clips = [document.current_clip]
    return save_rig(document.rig, path, clips=clips)


# ---------------------------------------------------------------------- the pose, skeleton, weights
def pose_to_dict(pose):
    """JSON-ready description of a pose (local transforms and Euler angles from rest)."""
    joints = {}
    for j, name in enumerate(pose.skeleton.names):
        joints[name] = {"translation": pose.translation[j].round(9).tolist(),
                        "rotation": pose.rotation[j].round(12).tolist(),
                        "scale": pose.scale[j].round(9).tolist(),
                        "euler_degrees_from_rest": pose.get_euler(j, degrees=True)
                        .round(6).tolist()}
    return {"format": "rigedit.pose", "version": 1, "rotation_order": "xyzw",
            "joints": joints}


def export_pose(document, path):
    """Write the current pose as JSON (:func:`pose_to_dict`), atomically."""
    write_json(path, pose_to_dict(document.pose))


def export_skeleton(document, path):
    """Write the skeleton as rigedit's skeleton JSON (with the rig's up axis), atomically."""
    save_skeleton(path, document.skeleton, up=document.rig.up)


def save_weights(document, path):
    """Write the skin weights to a ``.npz`` file (with the joint names), atomically."""
    b = document.rig.binding
    weights_npz.save_weights(path, b.indices, b.weights, document.skeleton.names)


def load_weights(document, path):
    """Replace the skin weights from a ``.npz`` file (mapped onto the skeleton's joints by
    name), as one undo step.

    Raises
    ------
    ValueError
        A file that is not weights, or not of this rig's vertex count or joints.
    """
    rig = document.rig
    indices, weights = weights_npz.load_weights(path, rig.skeleton, len(rig.vertices))
    document.set_weights(indices, weights, label=f"Load weights {Path(path).name}")
