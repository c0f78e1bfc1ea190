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

From step 2 to the end, SIGINT and SIGTERM are held and delivered afterwards, so an
interrupted command leaves the new state in place rather than for the next load to finish.

:func:`recover_interrupted_save` (run by ``read_rig_folder`` and at the start of every save)
finishes what a killed save left: a staging folder with a journal is applied again, which is
idempotent (a file already moved is no longer staged), so the folder loads as the new state;
one without a journal is deleted, so the folder loads as the old state.

A save holds an exclusive lock on the folder (``flock`` on the folder itself, released by the
system when the process dies; none on Windows), and so does the recovery: a load that starts
while another process saves waits for that save to finish instead of taking its half-written
staging folder for the litter of a crash. (A save that starts while a load is already reading
is not waited for.)

Which clip files a save replaces and deletes: :mod:`rigedit.io.clip_files`.
"""
from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import threading
from pathlib import Path, PurePosixPath

import numpy as np

from ..animation.clip_names import check_clip_name
from ..errors import RigFileError, RigWriteError
from .atomic import check_output_folder, fsync_folder, write_error, write_json
from .bundled import is_bundled
from .clip_files import (ANIMATIONS, clip_entry, loaded_clip_files, plan_clip_files,
                         remember_clip_files)
from ..compression import CompressedClip
from .clip_json import save_clip
from .compressed_file import save_compressed
from .data import as_rig_data
from .mesh import save_obj
from .skeleton_json import save_skeleton
from .morphs_npz import save_morphs
from .weights_npz import save_weights

__all__ = ["save_rig_folder_atomic", "recover_interrupted_save", "remember_clip_files",
           "loaded_clip_files", "is_bundled", "folder_lock", "STAGING", "JOURNAL"]

#: The staging folder inside a rig folder, and the journal inside it.
STAGING = ".rigedit-save"
JOURNAL = "COMMIT"


@contextlib.contextmanager
def folder_lock(folder, shared=False):
    """Hold an exclusive (or ``shared``) lock on ``folder`` for the block; waits for another
    process's. Saves and recoveries take it exclusively. A no-op where ``flock`` is missing."""
    try:
        import fcntl
        fd = os.open(folder, os.O_RDONLY)
    except (ImportError, OSError):
        yield
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_SH if shared else fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)   # releases the lock


# ---------------------------------------------------------------------- saving
def save_rig_folder_atomic(folder, rig, mesh_name="mesh.obj", allow_bundled=False):
    """Write ``rig`` as a rig folder so that the folder matches it exactly, crash-safely.

    Parameters
    ----------
    folder : str or Path
        Created when missing (its parent must exist).
    rig : RigData or Rig
        The rig's data (:class:`~rigedit.io.data.RigData`; a Rig gives its ``data()``).
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
    RigWriteError
        The folder cannot be written (disk full, permission denied, read-only): named, not
        its hidden staging folder; the folder is as it was (one this save created is removed).
    RigFileError
        A bundled folder, a missing parent folder, a foreign clip file in the way.
    ValueError
        An invalid or doubled clip name (nothing is written).
    """
    folder = Path(folder)
    rig = as_rig_data(rig)
    if not allow_bundled and is_bundled(folder):
        raise RigFileError(folder, "expected a folder of your own, got a bundled character "
                                   "(read-only): save it somewhere else")
    if PurePosixPath(mesh_name).name != mesh_name or Path(mesh_name).name != mesh_name:
        raise ValueError(f"mesh file name {mesh_name!r}: expected a plain file name")
    names = [check_clip_name(clip.name) for clip in rig.clips.values()]
    if len(set(names)) != len(names):
        raise ValueError(f"expected distinct clip names, got {sorted(names)}")
    check_output_folder(folder)
    created = not (folder.exists() or folder.is_symlink())
    try:
        folder.mkdir(exist_ok=True)
        with folder_lock(folder):
            _recover(folder)
            return _save(folder, rig, names, mesh_name)
    except BaseException as exc:
        if created:   # a new folder that did not get the rig: nothing is left behind
            with contextlib.suppress(OSError):
                _remove_tree(folder)
        raise _named(exc, folder) from None


def _named(exc, folder):
    """A write error of the save, naming the rig folder (the user's path) rather than the
    staging file or folder it happened to; other exceptions as they are."""
    if isinstance(exc, RigWriteError):
        return RigWriteError(folder, exc.problem, exc.errno, exc.strerror)
    new = write_error(exc, folder)
    if new is not exc:
        return new
    if isinstance(exc, RigFileError) and STAGING in Path(exc.path).parts:
        return RigWriteError(folder, exc.problem)
    return exc


def _referenced(rig):
    """The rig's mesh, weights and morph targets without the vertices no face uses.

    The mesh reader keeps only referenced vertices (stray points would take weights and widen
    bounding boxes), so a folder written with them would not load back: its weights would be
    for more vertices than its mesh has (a glTF primitive with unused vertices did this).

    Returns
    -------
    vertices (V', 3), faces (F, 3), indices (V', K), weights (V', K), morphs or None
    """
    vertices, faces = np.asarray(rig.vertices), np.asarray(rig.faces)
    indices, weights = np.asarray(rig.indices), np.asarray(rig.weights)
    morphs = rig.morphs
    used = np.zeros(len(vertices), dtype=bool)
    used[faces.ravel()] = True
    if used.all():
        return vertices, faces, indices, weights, morphs
    remap = np.cumsum(used) - 1
    if morphs is not None:
        morphs = morphs.subset(np.flatnonzero(used))
    return vertices[used], remap[faces], indices[used], weights[used], morphs


def _save(folder, rig, names, mesh_name):
    files, stale = plan_clip_files(folder, rig, names)

    stage = folder / STAGING
    _remove_tree(stage)
    try:
        (stage / ANIMATIONS).mkdir(parents=True)
        # a rig without a mesh (a BVH skeleton) has no mesh or weights file: "mesh": null
        meshless = len(rig.vertices) == 0
        morphs = None
        if not meshless:
            vertices, faces, indices, weights, morphs = _referenced(rig)
            save_obj(stage / mesh_name, vertices, faces, header=f"rigedit rig {rig.name}")
            save_weights(stage / "weights.npz", indices, weights, rig.skeleton.names)
        # morph targets (a glTF's or FBX's shapes) go with the mesh; their weight tracks
        # are in the clips' files
        if morphs is not None:
            save_morphs(stage / "morphs.npz", morphs)
        save_skeleton(stage / "skeleton.json", rig.skeleton, up=rig.up)
        for clip in rig.clips.values():
            if isinstance(clip, CompressedClip):
                save_compressed(stage / ANIMATIONS / files[clip.name], rig.skeleton,
                                {clip.name: clip})
            else:
                save_clip(stage / ANIMATIONS / files[clip.name], clip)
        clip_paths = {name: f"{ANIMATIONS}/{files[name]}" for name in sorted(files)}
        manifest = {"name": rig.name, "mesh": None if meshless else mesh_name,
                    "skeleton": "skeleton.json", "weights": "weights.npz", "up": rig.up,
                    "clips": clip_paths}
        if meshless:
            del manifest["weights"]
        if morphs is not None:
            manifest["morphs"] = "morphs.npz"
        write_json(stage / "rig.json", manifest)
        fsync_folder(stage / ANIMATIONS)
        fsync_folder(stage)
        journal = {"format": "rigedit.save-journal", "version": 1,
                   "replace": [*([] if meshless else [mesh_name, "weights.npz"]),
                               *([] if morphs is None else ["morphs.npz"]),
                               "skeleton.json", *clip_paths.values(), "rig.json"],
                   "delete": [f"{ANIMATIONS}/{f}" for f in stale]}
    except BaseException:
        _remove_tree(stage)   # nothing of the folder was touched yet
        raise
    # Ctrl-C or SIGTERM from the commit point on waits until the folder holds the new state,
    # so an interrupted command does not leave the rest of the save to the next load.
    with _signals_held():
        try:
            write_json(stage / JOURNAL, journal)   # the commit point
        except BaseException:
            _remove_tree(stage)
            raise
        fsync_folder(stage)
        _apply(folder, journal)
    return clip_paths


@contextlib.contextmanager
def _signals_held():
    """Hold SIGINT and SIGTERM for the block (main thread only: Python runs signal handlers
    there) and deliver them, to the handlers the program had, when it ends."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught = []
    previous = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        if signal.getsignal(sig) is not None:   # None: a handler Python cannot restore
            previous[sig] = signal.signal(sig, lambda signum, frame: caught.append(signum))
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        for sig in caught:
            signal.raise_signal(sig)


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
            ok = ok and (clip_entry(rel) is not None or (
                isinstance(rel, str) and PurePosixPath(rel).name == rel
                and rel not in ("", ".", "..", STAGING) and "\\" not in rel))
        ok = ok and all(clip_entry(rel) is not None for rel in journal["delete"])
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
        return None   # the common case, without a lock
    with folder_lock(folder):
        return _recover(folder)


def _recover(folder):
    stage = folder / STAGING
    if not (stage.exists() or stage.is_symlink()):
        return None   # a save in progress meanwhile finished
    try:
        if not (stage / JOURNAL).is_file():
            _remove_tree(stage)
            return "discarded"
        _apply(folder, _read_journal(stage / JOURNAL))
    except OSError as exc:   # named by the rig folder: the staging folder is rigedit's own
        raise RigWriteError(folder, f"an interrupted save could not be finished: "
                                    f"{exc.strerror or exc}", exc.errno, exc.strerror) \
            from None
    return "completed"
