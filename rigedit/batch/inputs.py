"""A batch's inputs: files, folders (searched for what the job reads) and globs, expanded into
one sorted list of paths, and the content hashes the manifest records for them.

Inputs travel to the workers as these paths, never as loaded meshes: a cluster's workers read
them from the shared file system.
"""
from __future__ import annotations

import glob
import hashlib
import os
from pathlib import Path

from ..io.bundled import BUNDLED, resolve_rig_path
from ..io.mesh import MESH_SUFFIXES
from ..io.registry import RIG_FILE_SUFFIXES

__all__ = ["BatchUsageError", "JOB_SUFFIXES", "expand_inputs", "rig_source", "content_hash",
           "quick_stamp"]

#: What each job reads from a folder it is given (a rig folder is also an input of the jobs
#: that read rigs: a folder holding a ``skeleton.json`` is taken whole, not searched).
JOB_SUFFIXES = {
    "autorig": MESH_SUFFIXES + (".glb", ".gltf"),
    "retarget": (".bvh", ".glb", ".gltf", ".fbx"),
    "render": RIG_FILE_SUFFIXES,
    "convert": RIG_FILE_SUFFIXES,
    "compress": RIG_FILE_SUFFIXES,
    "noop": (),
}

#: Jobs whose inputs may be rig folders and bundled names.
_RIG_JOBS = ("render", "convert", "compress", "retarget")

#: At most this many inputs (a typo such as ``/`` must not make a list of millions).
MAX_INPUTS = 1_000_000


class BatchUsageError(ValueError):
    """Bad input found before any work: an option that makes no sense, an input that does not
    exist, an OUTDIR that cannot be written, a scheduler that does not answer. The command
    prints it as one line and exits 2."""


def _is_rig_folder(path):
    return path.is_dir() and (path / "skeleton.json").is_file()


def _search(folder, suffixes, take_rig_folders):
    """Files under ``folder`` whose suffix is one of ``suffixes`` (hidden entries and
    rig folders' insides skipped; rig folders themselves when ``take_rig_folders``)."""
    found = []
    for root, dirs, files in os.walk(folder):
        here = Path(root)
        keep = []
        for d in sorted(dirs):
            if d.startswith("."):
                continue
            if _is_rig_folder(here / d):
                if take_rig_folders:
                    found.append(here / d)
                continue
            keep.append(d)
        dirs[:] = keep
        found += [here / f for f in files
                  if not f.startswith(".") and Path(f).suffix.lower() in suffixes]
    return found


def expand_inputs(job, inputs):
    """Every path a batch of ``job`` reads from ``inputs``, sorted and without repeats.

    Parameters
    ----------
    job : str
        A key of :data:`JOB_SUFFIXES`.
    inputs : list of str or os.PathLike
        Files (taken as they are, whatever their suffix: a wrong one is that task's error),
        folders (searched for the job's suffixes; a rig folder is one input of the rig jobs),
        globs (``**`` searches below a folder), and for the rig jobs bundled names
        (``humanoid``, ``quadruped``).

    Returns
    -------
    list[Path]
        Absolute paths (bundled names stay names).

    Raises
    ------
    BatchUsageError
        An input that exists nowhere and matches nothing, or no input at all.
    """
    suffixes = JOB_SUFFIXES[job]
    rigs = job in _RIG_JOBS
    out = set()
    for text in inputs:
        text = str(text)
        path = Path(text).expanduser()
        if rigs and text in BUNDLED and not path.exists():
            out.add(Path(text))
        elif _is_rig_folder(path) and rigs:
            out.add(path.resolve())
        elif path.is_dir():
            found = _search(path, suffixes, rigs)
            if not found:
                raise BatchUsageError(f"{text}: no {job} input in this folder (looked for "
                                      f"{', '.join(suffixes)})")
            out.update(p.resolve() for p in found)
        elif path.exists():
            out.add(path.resolve())
        elif glob.has_magic(text):
            found = [Path(p) for p in glob.iglob(os.path.expanduser(text), recursive=True)]
            found = [p for p in found if p.is_file() or (rigs and _is_rig_folder(p))]
            if not found:
                raise BatchUsageError(f"{text}: the pattern matches no file")
            out.update(p.resolve() for p in found)
        else:
            raise BatchUsageError(f"{text}: no such file or folder")
        if len(out) > MAX_INPUTS:
            raise BatchUsageError(f"{text}: more than {MAX_INPUTS} inputs")
    if not out:
        raise BatchUsageError(f"expected at least one {job} input, got none")
    return sorted(out, key=str)


def rig_source(text):
    """A rig given as an option (``--to``, ``--template``): a bundled name stays a name, a path
    becomes absolute; ``BatchUsageError`` when it is neither."""
    path = Path(str(text)).expanduser()
    if str(text) in BUNDLED and not path.exists():
        return str(text)
    if not path.exists():
        raise BatchUsageError(f"{text}: no such rig (expected a file, a rig folder or one of "
                              f"{', '.join(BUNDLED)})")
    return str(path.resolve())


def _files_of(path):
    """The files whose bytes make ``path``: itself, or a folder's files (sorted, relative
    names included in the hash so a rename changes it)."""
    if path.is_dir():
        return sorted((p for p in path.rglob("*") if p.is_file()), key=str)
    return [path]


def content_hash(source):
    """``"sha256:<hex>"`` of a file's bytes, or of a folder's files and their relative names;
    a bundled name hashes its bundled folder.

    Parameters
    ----------
    source : str or Path

    Raises
    ------
    OSError
        The file cannot be read.
    """
    path = resolve_rig_path(str(source)) if str(source) in BUNDLED else Path(source)
    h = hashlib.sha256()
    for f in _files_of(path):
        if f != path:
            h.update(str(f.relative_to(path)).encode() + b"\0")
        with open(f, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
    return "sha256:" + h.hexdigest()


def quick_stamp(source):
    """``[size, mtime_ns]`` of a file (a folder: summed over its files), the cheap check a
    resume makes before hashing again; None when it cannot be read."""
    path = resolve_rig_path(str(source)) if str(source) in BUNDLED else Path(source)
    try:
        stats = [f.stat() for f in _files_of(path)]
    except OSError:
        return None
    return [sum(s.st_size for s in stats), max((s.st_mtime_ns for s in stats), default=0)]
