"""Rig folders: a mesh, a skeleton JSON, ``animations/*.json`` and optional weights.

Layouts read::

    my_rig/                         elk_project/
      rig.json      (optional)        models/*.obj       (parts merged)
      mesh.obj|ply|stl|vtk|vtu|vtp    skeleton/skeleton.json
      skeleton.json                   animations/*.json
      weights.npz   (optional)
      animations/*.json

``rig.json`` may name the files and the up axis:
``{"name": "quadruped", "mesh": "mesh.obj", "skeleton": "skeleton.json",
"weights": "weights.npz", "up": "y"}``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import RigFileError
from .clip_files import CLIP_SUFFIXES
from .clip_json import load_clip
from .compressed_file import read_clip_file
from .data import RigData, RigMeta, WeightsComputedWarning, build_rig
from .frames import change_axes, resolve_folder_frames
from .jsonfile import choice, name, read_json, relative_path
from .mesh import MESH_SUFFIXES, load_mesh
from .rig_save import (STAGING, folder_lock, recover_interrupted_save, remember_clip_files,
                       save_rig_folder_atomic)
from .paths import list_folder, os_problem, what_is
from .skeleton_json import UP_AXES, load_skeleton
from .morphs_npz import load_morphs
from .weights_npz import load_weights, weights_vertex_count

__all__ = ["read_rig_folder", "write_rig_folder", "load_rig_folder", "save_rig_folder",
           "find_rig_files", "WeightsComputedWarning"]


def _meshes_in(folder):
    # Everything with a mesh suffix, not only regular files: a FIFO or a folder named
    # mesh.obj is reported by load_mesh ("expected a regular file") rather than skipped.
    return [p for p in list_folder(folder) if p.suffix.lower() in MESH_SUFFIXES]


def _exists(path):
    return what_is(path) is not None


def _is_dir(path):
    return what_is(path) == "a folder"


def read_manifest(path):
    """``rig.json`` checked: names as strings, files as relative names, ``up`` y or z."""
    manifest = read_json(path)
    if not isinstance(manifest, dict):
        raise RigFileError(path, f"expected a JSON object, got {type(manifest).__name__}")
    out = {}
    for key in ("mesh", "skeleton", "weights", "morphs"):
        if manifest.get(key) is not None:
            out[key] = relative_path(path, manifest[key], repr(key))
    if "mesh" in manifest and manifest["mesh"] is None:
        if manifest.get("weights") is not None or _exists(path.parent / "weights.npz"):
            raise RigFileError(path, "expected 'mesh' to name the mesh file, got null in a "
                                     "folder with skin weights (null is a rig without a mesh)")
        out["mesh"] = None   # a rig without a mesh

    if manifest.get("name") is not None:
        out["name"] = name(path, manifest["name"], "'name'")
    for key in ("up", "skeleton_up"):   # the mesh's and the skeleton's (io/frames.py)
        if manifest.get(key) is not None:
            out[key] = choice(path, manifest[key], repr(key), UP_AXES)
    return out


def find_rig_files(folder):
    """Locate the files of a rig folder.

    Returns
    -------
    dict with ``meshes`` (list of Path), ``skeleton`` (Path), ``weights`` (Path or None),
    ``animations`` (list of Path), ``manifest`` (dict).

    Raises
    ------
    RigFileError
        No mesh or skeleton; several meshes at the top of the folder and no ``rig.json``
        naming one (the elk layout's ``models/*.obj`` parts are merged, that is the layout);
        a malformed ``rig.json``; an ``animations`` that is not a folder.
    """
    folder = Path(folder)
    if not _is_dir(folder):
        raise RigFileError(folder, "expected a rig folder, got " +
                           ("a file" if _exists(folder) else "nothing (not found)"))
    manifest = read_manifest(folder / "rig.json") if _exists(folder / "rig.json") else {}
    if "mesh" in manifest:   # "mesh": null is a rig without a mesh (a BVH skeleton)
        meshes = [] if manifest["mesh"] is None else [folder / manifest["mesh"]]
    else:
        meshes = _meshes_in(folder)
        if len(meshes) > 1:
            raise RigFileError(folder, f"expected one mesh or a rig.json naming one, got "
                                       f"{len(meshes)}: {', '.join(p.name for p in meshes)}")
        if not meshes and _is_dir(folder / "models"):
            meshes = _meshes_in(folder / "models")
    if not meshes and "mesh" not in manifest:
        raise RigFileError(folder, f"expected a mesh file ({', '.join(MESH_SUFFIXES)}) in the "
                                   "folder or in models/, got none")
    if "skeleton" in manifest:
        skeleton = folder / manifest["skeleton"]
    else:
        candidates = [folder / "skeleton.json", folder / "skeleton" / "skeleton.json"]
        skeleton = next((c for c in candidates if _exists(c)), None)
        if skeleton is None:
            raise RigFileError(folder, "expected skeleton.json or skeleton/skeleton.json, got "
                                       "neither")
    weights = folder / manifest.get("weights", "weights.npz")
    anim_dir = folder / "animations"
    animations = []
    if _exists(anim_dir):
        if not anim_dir.is_dir():
            raise RigFileError(anim_dir, "expected a folder of clip files, got a file")
        animations = [p for p in list_folder(anim_dir) if p.suffix.lower() in CLIP_SUFFIXES]
    morphs = folder / manifest["morphs"] if "morphs" in manifest else None
    if morphs is not None and not _exists(morphs):
        raise RigFileError(folder / "rig.json", f"expected the morph targets it names "
                                                f"({manifest['morphs']}), got no such file")
    return {"meshes": meshes, "skeleton": skeleton,
            "weights": weights if meshes and _exists(weights) else None,  # none without a mesh
            "morphs": morphs if meshes else None,
            "animations": animations, "manifest": manifest}


def read_rig_folder(folder):
    """Read a rig folder (either layout) into a :class:`~rigedit.io.data.RigData`.

    ``indices``/``weights`` are None when the folder has no weights file (the mesh is then
    welded: the elk layout's OBJ exports split vertices at seams); ``meta.clip_files`` names
    the file of every clip, ``meta.notes["frames"]`` an axis decision. Warns
    ``UnknownJointsWarning`` for clips naming joints the skeleton lacks.

    The read holds a shared lock on the folder (:func:`~rigedit.io.rig_save.folder_lock`),
    which a save holds exclusively: a load while another process saves the same folder
    waits for it and reads the old state or the new one whole, never a mix of the two.
    """
    folder = Path(folder)
    try:
        for _ in range(3):
            if _is_dir(folder):
                recover_interrupted_save(folder)   # a save killed part-way: finish or undo it
            with folder_lock(folder, shared=True):
                if _is_dir(folder) and (folder / STAGING).exists():
                    continue   # a save was killed between the recovery and the lock
                return _read(folder)
        raise RigFileError(folder, "expected the folder to stay still while it is read, got "
                                   "saves interrupted again and again")
    except OSError as exc:   # an unreadable folder (chmod 000), a name the system refuses
        raise RigFileError(getattr(exc, "filename", None) or folder, os_problem(exc)) \
            from None


def _read(folder):
    files = find_rig_files(folder)
    skeleton, meta = load_skeleton(files["skeleton"])

    def read_mesh(weld):
        if not files["meshes"]:
            return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
        parts = [load_mesh(p, weld=weld) for p in files["meshes"]]
        offsets = np.cumsum([0] + [len(v) for v, _ in parts[:-1]])
        return (np.concatenate([v for v, _ in parts]),
                np.concatenate([f + o for (_, f), o in zip(parts, offsets)]))

    # A weights file fixes the vertex order: keep the mesh's vertices as they are when the
    # weights fit them (a saved rig whose mesh has coincident vertices, such as split
    # normals), and weld seam duplicates otherwise (the elk layout's OBJ exports).
    vertices, faces = read_mesh(weld=files["weights"] is None)   # read once without weights
    indices = weights = None
    if files["weights"] is not None:
        if weights_vertex_count(files["weights"]) != len(vertices):
            vertices, faces = read_mesh(weld=True)
        indices, weights = load_weights(files["weights"], skeleton, len(vertices))
    elif not files["meshes"]:
        indices, weights = np.zeros((0, 1), dtype=np.int64), np.zeros((0, 1))
    # the elk layout's skeleton may be Z up over a Y-up mesh (rigedit/io/frames.py)
    skeleton, up, frames_note, clip_change = resolve_folder_frames(
        folder, skeleton, meta, vertices, files["manifest"])
    clips, sources = {}, {}
    for path in files["animations"]:
        found = ([load_clip(path, skeleton)] if path.suffix.lower() == ".json"
                 else list(read_clip_file(path, skeleton)[1].values()))
        for clip in found:
            if clip.name in sources:
                raise RigFileError(path, f"expected one file per clip name, got clip "
                                         f"{clip.name!r} in both {sources[clip.name]} and "
                                         f"{path}")
            clips[clip.name], sources[clip.name] = clip, path
    if clip_change is not None and any(p.suffix.lower() == ".rgc" for p in sources.values()):
        raise RigFileError(folder, "expected JSON clips in a folder whose skeleton changes "
                                   "axes on reading, got a compressed (.rgc) clip")
    if clip_change is not None:   # rigedit's formats: skeleton and clips change together
        skeleton, clips = change_axes(skeleton, clips, clip_change)
    morphs = None if files["morphs"] is None else load_morphs(files["morphs"], len(vertices))
    data = RigData(skeleton, vertices, faces, indices, weights, clips, morphs=morphs,
                   name=files["manifest"].get("name", folder.resolve().name), up=up,
                   meta=RigMeta(source=folder, format="folder"))
    remember_clip_files(data, sources)   # a later save replaces exactly these
    if frames_note:
        data.meta.notes["frames"] = frames_note
    return data


def load_rig_folder(folder, weights_method=None):
    """Load a rig folder into a :class:`~rigedit.rig.Rig` (:func:`read_rig_folder`, then
    ``Rig.from_data``, which computes the weights of a folder without a weights file, warning
    :class:`WeightsComputedWarning`)."""
    return build_rig(read_rig_folder(folder), weights_method=weights_method)


def save_rig_folder(folder, rig, mesh_name="mesh.obj", allow_bundled=False):
    """Write ``rig`` as a rig folder in rigedit's formats so that the folder matches it: a
    clip deleted or renamed since it was loaded or last saved loses its file, files rigedit
    did not write stay, and a crash at any moment leaves the old or the new state (see
    :mod:`rigedit.io.rig_save`). A bundled character is refused unless ``allow_bundled``.

    Returns
    -------
    clip_files : dict[str, str]
        Clip name -> file written, relative to ``folder``.
    """
    return save_rig_folder_atomic(folder, rig, mesh_name=mesh_name, allow_bundled=allow_bundled)


def write_rig_folder(data, folder, clips=None):
    """The registry's writer (:mod:`rigedit.io.registry`): :func:`save_rig_folder` of every
    clip; a folder holds them all, so a selection is refused."""
    if clips is not None:
        raise RigFileError(folder, "expected no clip selection for a rig folder (it holds "
                                   "every clip), got --clip")
    return save_rig_folder(folder, data)
