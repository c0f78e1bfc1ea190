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

import warnings
from pathlib import Path

import numpy as np

from ..errors import RigFileError
from ..rig import Rig
from .atomic import write_json
from .clip_json import load_clip, save_clip
from .jsonfile import read_json
from .mesh import MESH_SUFFIXES, load_mesh, save_obj
from .skeleton_json import load_skeleton, save_skeleton
from .weights_npz import load_weights, save_weights, weights_vertex_count

__all__ = ["load_rig_folder", "save_rig_folder", "find_rig_files", "WeightsComputedWarning"]


class WeightsComputedWarning(UserWarning):
    """A rig had no weights file, so weights were computed."""


def _meshes_in(folder):
    return sorted(p for p in folder.iterdir() if p.suffix.lower() in MESH_SUFFIXES and p.is_file())


def find_rig_files(folder):
    """Locate the files of a rig folder.

    Returns
    -------
    dict with ``meshes`` (list of Path), ``skeleton`` (Path), ``weights`` (Path or None),
    ``animations`` (list of Path), ``manifest`` (dict).
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise RigFileError(folder, "expected a rig folder, got " +
                           ("a file" if folder.exists() else "nothing (not found)"))
    manifest = read_json(folder / "rig.json") if (folder / "rig.json").is_file() else {}
    if not isinstance(manifest, dict):
        raise RigFileError(folder / "rig.json", "expected a JSON object")
    if "mesh" in manifest:
        meshes = [folder / manifest["mesh"]]
    else:
        meshes = _meshes_in(folder) or (
            _meshes_in(folder / "models") if (folder / "models").is_dir() else [])
    if not meshes:
        raise RigFileError(folder, f"expected a mesh file ({', '.join(MESH_SUFFIXES)}) in the "
                                   "folder or in models/, got none")
    if "skeleton" in manifest:
        skeleton = folder / manifest["skeleton"]
    else:
        candidates = [folder / "skeleton.json", folder / "skeleton" / "skeleton.json"]
        skeleton = next((c for c in candidates if c.is_file()), None)
        if skeleton is None:
            raise RigFileError(folder, "expected skeleton.json or skeleton/skeleton.json, got "
                                       "neither")
    weights = folder / manifest.get("weights", "weights.npz")
    anim_dir = folder / "animations"
    animations = sorted(anim_dir.glob("*.json")) if anim_dir.is_dir() else []
    return {"meshes": meshes, "skeleton": skeleton,
            "weights": weights if weights.is_file() else None,
            "animations": animations, "manifest": manifest}


def load_rig_folder(folder, weights_method="idw"):
    """Load a rig folder (either layout) into a :class:`Rig`.

    Warns :class:`WeightsComputedWarning` when the weights were computed because the folder
    has none, and ``UnknownJointsWarning`` for clips naming joints the skeleton lacks.
    """
    folder = Path(folder)
    files = find_rig_files(folder)
    skeleton, meta = load_skeleton(files["skeleton"])

    def read_mesh(weld):
        parts = [load_mesh(p, weld=weld) for p in files["meshes"]]
        offsets = np.cumsum([0] + [len(v) for v, _ in parts[:-1]])
        return (np.concatenate([v for v, _ in parts]),
                np.concatenate([f + o for (_, f), o in zip(parts, offsets)]))

    # A weights file fixes the vertex order: keep the mesh's vertices as they are when the
    # weights fit them (a saved rig whose mesh has coincident vertices, such as split
    # normals), and weld seam duplicates otherwise (the elk layout's OBJ exports).
    vertices, faces = read_mesh(weld=False)
    indices = weights = None
    if files["weights"] is not None:
        if weights_vertex_count(files["weights"]) != len(vertices):
            vertices, faces = read_mesh(weld=True)
        indices, weights = load_weights(files["weights"], skeleton, len(vertices))
    else:
        vertices, faces = read_mesh(weld=True)
        warnings.warn(f"{folder}: no weights file; computed weights by inverse distance to "
                      f"the bones ({weights_method})", WeightsComputedWarning, stacklevel=2)
    clips = {}
    for path in files["animations"]:
        clip = load_clip(path, skeleton)
        clips[clip.name] = clip
    up = files["manifest"].get("up", meta["up"])
    name = files["manifest"].get("name", folder.resolve().name)
    return Rig(skeleton, vertices, faces, indices, weights, clips, name=name, up=up,
               weights_method=weights_method, path=folder)


def save_rig_folder(folder, rig, mesh_name="mesh.obj"):
    """Write ``rig`` as a rig folder in rigedit's formats; each file written atomically."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    save_obj(folder / mesh_name, rig.vertices, rig.faces, header=f"rigedit rig {rig.name}")
    save_skeleton(folder / "skeleton.json", rig.skeleton, up=rig.up)
    save_weights(folder / "weights.npz", rig.binding.indices, rig.binding.weights,
                 rig.skeleton.names)
    for clip in rig.clips.values():
        save_clip(folder / "animations" / f"{clip.name}.json", clip)
    write_json(folder / "rig.json", {"name": rig.name, "mesh": mesh_name,
                                     "skeleton": "skeleton.json", "weights": "weights.npz",
                                     "up": rig.up})
