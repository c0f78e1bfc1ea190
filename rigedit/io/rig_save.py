"""Saving a whole rig folder: the folder ends up holding exactly the rig, and a crash at any
moment of a save leaves either the old state or the new one, never a mix.

The protocol
------------
1. Every file of the new state is written into ``FOLDER/.rigedit-save/`` (same layout) and
   synced to disk. The folder itself is not touched yet.
2. The journal ``.rigedit-save/COMMIT`` is written atomically (temporary file, fsync, rename):
   the files to move into place and the stale clip files to delete. Its appearance is the
   commit point.
3. The journal is applied: each staged file is renamed over its place (``os.replace``, atomic
   on one file system, which the staging folder inside the rig folder guarantees), the stale
   clip files are deleted, the folders are synced.
4. The journal is deleted, then the staging folder.

:func:`recover_interrupted_save` (run by ``load_rig_folder`` and at the start of every save)
finishes what a killed save left: a staging folder with a journal is applied again, which is
idempotent (a file already moved is no longer staged), so the folder loads as the new state;
one without a journal is deleted, so the folder loads as the old state.

Which clip files are rigedit's
------------------------------
A save deletes from ``animations/`` only clip files that are rigedit's:

- those the folder's ``rig.json`` lists under ``"clips"`` (``{name: "animations/FILE.json"}``,
  written by every save), and
- those the saved rig's clips were read from, when they are in this folder
  (``load_rig_folder`` records them with :func:`remember_clip_files`).

- a clip file it has no record of that holds a clip of a name being saved becomes that clip's
  file (a document recovered after a crash, or saved over a folder it did not come from).

A clip that is deleted or renamed in the editor is therefore gone after the save. Every other
file is left as it is: a README, pictures, a clip file of another name someone copied in after
the rig was loaded (it loads as one more clip next time). A second file holding a clip of a
name being saved is an error (the folder would not load), named in the message, before
anything is written. The rig's own files (``rig.json``, the mesh, ``skeleton.json``,
``weights.npz``) are replaced.
"""
from __future__ import annotations

import contextlib
import json
import os
import shutil
import weakref
from pathlib import Path, PurePosixPath

from ..animation.clip_names import check_clip_name, clip_file_stem, name_key
from ..errors import RigFileError
from .atomic import check_output_folder, fsync_folder, write_json
from .clip_json import save_clip
from .mesh import save_obj
from .skeleton_json import save_skeleton
from .weights_npz import save_weights

__all__ = ["save_rig_folder_atomic", "recover_interrupted_save", "remember_clip_files",
           "loaded_clip_files", "is_bundled", "STAGING", "JOURNAL"]

#: The staging folder inside a rig folder, and the journal inside it.
STAGING = ".rigedit-save"
JOURNAL = "COMMIT"
ANIMATIONS = "animations"

# Rig -> {clip name: resolved path} of the files its clips were loaded from. Kept beside the
# rig rather than in it: only saving needs it, and a rig built in code has none.
_LOADED_FROM = weakref.WeakKeyDictionary()


def remember_clip_files(rig, files):
    """Record that ``rig``'s clips were read from ``files`` (``{clip name: path}``).

    ``load_rig_folder`` calls it; code that rebuilds a rig from a copy of it (a recovery
    snapshot) can pass on :func:`loaded_clip_files` of the original, so that a save over the
    original folder still deletes the files of clips deleted since."""
    _LOADED_FROM[rig] = {name: Path(p).resolve() for name, p in files.items()}


def loaded_clip_files(rig):
    """``{clip name: path}`` of the files ``rig``'s clips were read from (empty for a rig
    built in code)."""
    return dict(_LOADED_FROM.get(rig, {}))


def is_bundled(path):
    """True when ``path`` is (inside) a bundled character or the installed package: those are
    read-only for the editor (File > Save asks for a new place)."""
    import rigedit

    package = Path(rigedit.__file__).resolve().parent
    roots = {Path(rigedit.ASSETS_DIR).resolve(), package, package.parent / "assets"}
    path = Path(path).resolve()
    return any(path == root or root in path.parents for root in roots)


# ---------------------------------------------------------------------- planning
def _clip_entry(rel):
    """``rel`` ("animations/NAME.json") as a file name inside ``animations/``, or None when it
    is anything else (a save never deletes outside ``animations/``)."""
    if not isinstance(rel, str):
        return None
    parts = PurePosixPath(rel).parts
    if (len(parts) == 2 and parts[0] == ANIMATIONS and parts[1].endswith(".json")
            and parts[1] not in (".", "..") and "\\" not in parts[1]):
        return parts[1]
    return None


def _previous_manifest(folder):
    try:
        data = json.loads((folder / "rig.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def _declared_name(path):
    """The clip name a JSON file declares, or None (unreadable, not a clip)."""
    try:
        if path.stat().st_size > 64 * 2**20:
            return None
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if isinstance(data, dict) and ("tracks" in data or "keyframes" in data):
        return str(data.get("name") or path.stem)
    return None


def plan_clip_files(folder, rig, names):
    """File names for the clips being saved, and the stale clip files to delete.

    A clip keeps the file it was loaded from or last saved to (``rig.json``'s record). A clip
    file rigedit has no record of that holds a clip of a name being saved is that clip's file
    (a recovered or re-opened document saved over its folder) unless the clip already has
    one. A new or renamed clip gets a file name derived from its name
    (:func:`clip_file_stem`), never one that another file already has.

    Returns
    -------
    files : dict[str, str]
        Clip name -> file name inside ``animations/``.
    stale : list[str]
        File names inside ``animations/`` to delete.

    Raises
    ------
    RigFileError
        A file rigedit has no record of holds a clip of a name being saved that has its own
        file already: the folder would hold that name twice.
    """
    anim = (folder / ANIMATIONS).resolve()
    previous = {}   # clip name -> file name in animations/, for rigedit's files
    recorded = _previous_manifest(folder).get("clips")
    for name, rel in (recorded.items() if isinstance(recorded, dict) else ()):
        file = _clip_entry(rel)
        if file is not None:
            previous.setdefault(name, file)
    for name, path in _LOADED_FROM.get(rig, {}).items():
        if path.parent == anim:
            previous[name] = path.name
    present = sorted(p.name for p in anim.iterdir()) if anim.is_dir() else []
    on_disk = {name_key(f) for f in present}
    ours = {name_key(f) for f in previous.values()}
    for file in present:
        if name_key(file) in ours or not file.endswith(".json"):
            continue
        declared = _declared_name(anim / file)
        if declared not in names:
            continue
        if declared in previous and name_key(previous[declared]) in on_disk:
            raise RigFileError(anim / file, f"holds a clip {declared!r}, and so does "
                               f"{previous[declared]}, which this save writes: expected one "
                               "file per clip name (move the file away or rename the clip)")
        previous[declared] = file
        ours.add(name_key(file))
    used = {name_key(f) for f in present if name_key(f) not in ours}
    files = {}
    for name in names:   # first the clips that keep their file
        file = previous.get(name)
        if file is not None and name_key(file) not in used:
            files[name] = file
            used.add(name_key(file))
    for name in names:
        if name not in files:
            files[name] = clip_file_stem(name, used) + ".json"
            used.add(name_key(files[name]))
    kept = {name_key(f) for f in files.values()}
    stale = sorted(f for f in present if name_key(f) in ours and name_key(f) not in kept
                   and f.endswith(".json"))
    return files, stale


# ---------------------------------------------------------------------- saving
def save_rig_folder_atomic(folder, rig, mesh_name="mesh.obj", allow_bundled=False):
    """Write ``rig`` as a rig folder so that the folder matches it exactly, crash-safely.

    Parameters
    ----------
    folder : str or Path
        Created when missing (its parent must exist).
    rig : Rig
    mesh_name : str
        File name of the OBJ mesh.
    allow_bundled : bool
        Allow writing into a bundled character (``assets/build.py`` only).

    Returns
    -------
    clip_files : dict[str, str]
        Clip name -> path written, relative to ``folder``.

    Raises
    ------
    RigFileError
        A bundled folder, a missing parent folder, a foreign clip file in the way.
    ValueError
        An invalid or doubled clip name (nothing is written).
    """
    folder = Path(folder)
    if not allow_bundled and is_bundled(folder):
        raise RigFileError(folder, "expected a folder of your own, got a bundled character "
                                   "(read-only): save it somewhere else")
    if PurePosixPath(mesh_name).name != mesh_name or Path(mesh_name).name != mesh_name:
        raise ValueError(f"mesh file name {mesh_name!r}: expected a plain file name")
    names = [check_clip_name(clip.name) for clip in rig.clips.values()]
    if len(set(names)) != len(names):
        raise ValueError(f"expected distinct clip names, got {sorted(names)}")
    check_output_folder(folder)
    folder.mkdir(exist_ok=True)
    recover_interrupted_save(folder)
    files, stale = plan_clip_files(folder, rig, names)

    stage = folder / STAGING
    _remove_tree(stage)
    try:
        (stage / ANIMATIONS).mkdir(parents=True)
        save_obj(stage / mesh_name, rig.vertices, rig.faces, header=f"rigedit rig {rig.name}")
        save_skeleton(stage / "skeleton.json", rig.skeleton, up=rig.up)
        save_weights(stage / "weights.npz", rig.binding.indices, rig.binding.weights,
                     rig.skeleton.names)
        for clip in rig.clips.values():
            save_clip(stage / ANIMATIONS / files[clip.name], clip)
        clip_paths = {name: f"{ANIMATIONS}/{files[name]}" for name in sorted(files)}
        write_json(stage / "rig.json", {"name": rig.name, "mesh": mesh_name,
                                        "skeleton": "skeleton.json", "weights": "weights.npz",
                                        "up": rig.up, "clips": clip_paths})
        fsync_folder(stage / ANIMATIONS)
        fsync_folder(stage)
        journal = {"format": "rigedit.save-journal", "version": 1,
                   "replace": [mesh_name, "skeleton.json", "weights.npz",
                               *clip_paths.values(), "rig.json"],
                   "delete": [f"{ANIMATIONS}/{f}" for f in stale]}
        write_json(stage / JOURNAL, journal)   # the commit point
    except BaseException:
        _remove_tree(stage)   # nothing of the folder was touched yet
        raise
    fsync_folder(stage)
    _apply(folder, journal)
    return clip_paths


def _remove_tree(path):
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    elif path.exists() or path.is_symlink():
        path.unlink()


def _apply(folder, journal):
    """Move the staged files into place, delete the stale ones, drop the journal and the
    staging folder. Safe to run again after a crash at any point of a previous run."""
    stage = folder / STAGING
    for rel in journal["replace"]:
        src, dst = stage / rel, folder / rel
        if src.exists():
            dst.parent.mkdir(exist_ok=True)
            os.replace(src, dst)
        elif not dst.is_file():
            raise RigFileError(stage / JOURNAL, f"lists {rel}, which is neither staged nor "
                                                "in place: the save cannot be completed")
    for rel in journal["delete"]:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(folder / rel)
    fsync_folder(folder / ANIMATIONS)
    fsync_folder(folder)
    # From here on the staging folder is only litter (and applying the journal again after a
    # power cut that forgot this deletion is harmless), so no fsync.
    os.unlink(stage / JOURNAL)
    _remove_tree(stage)


def _read_journal(path):
    try:
        journal = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise RigFileError(path, f"expected a save journal, got an unreadable file ({exc})") \
            from None
    ok = (isinstance(journal, dict) and isinstance(journal.get("replace"), list)
          and isinstance(journal.get("delete"), list))
    if ok:
        for rel in journal["replace"]:
            ok = ok and (_clip_entry(rel) is not None or (
                isinstance(rel, str) and PurePosixPath(rel).name == rel
                and rel not in ("", ".", "..", STAGING) and "\\" not in rel))
        ok = ok and all(_clip_entry(rel) is not None for rel in journal["delete"])
        ok = ok and not set(journal["replace"]) & set(journal["delete"])
    if not ok:
        raise RigFileError(path, "expected a save journal listing files of the rig folder "
                                 "to replace and clip files to delete, got something else")
    return journal


def recover_interrupted_save(folder):
    """Finish or undo a save that was killed part-way (see the module's docstring).

    Returns
    -------
    outcome : {None, "completed", "discarded"}
        None when no save was interrupted; ``"completed"`` when the new state was put in
        place; ``"discarded"`` when the unfinished new state was deleted (the old one stays).

    Raises
    ------
    RigFileError
        When the folder cannot be written (a read-only copy) or the journal is damaged.
    """
    folder = Path(folder)
    stage = folder / STAGING
    if not (stage.exists() or stage.is_symlink()):
        return None
    try:
        if not (stage / JOURNAL).is_file():
            _remove_tree(stage)
            return "discarded"
        _apply(folder, _read_journal(stage / JOURNAL))
    except OSError as exc:
        raise RigFileError(stage, f"an interrupted save could not be finished: "
                                  f"{exc.strerror or exc}") from None
    return "completed"
