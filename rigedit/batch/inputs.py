"""A batch's inputs: files, folders (searched for what the job reads) and globs, expanded into
one sorted list of paths, and the content hashes the manifest records for them.

Inputs travel to the workers as these paths, never as loaded meshes: a cluster's workers read
them from the shared file system.
"""
from __future__ import annotations

import fnmatch
import glob
import hashlib
import os
from pathlib import Path

from ..io.bundled import BUNDLED, resolve_rig_path
from ..io.mesh import MESH_SUFFIXES
from ..io.registry import RIG_FILE_SUFFIXES

__all__ = ["BatchUsageError", "JOB_SUFFIXES", "expand_inputs", "rig_source", "content_hash",
           "quick_stamp", "shown", "name_bytes"]

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


def name_bytes(text):
    """The bytes of a file name as Python holds it: a name that is not UTF-8 (``caf\\xe9.bvh``
    from an old archive) is ``caf\\udce9``, which ``str.encode`` refuses; a lone surrogate
    that is no byte of a name (a hand-edited manifest) becomes ``?``."""
    try:
        return os.fsencode(str(text))
    except UnicodeEncodeError:
        return str(text).encode("utf-8", "replace")


def shown(text):
    """``text`` fit for a UTF-8 page or terminal: a name's undecodable bytes as U+FFFD."""
    return name_bytes(text).decode("utf-8", "replace")


def _is_rig_folder(path):
    return path.is_dir() and (path / "skeleton.json").is_file()


def _walk(folder, skip=None, skipped=None):
    """``os.walk`` of ``folder`` that follows symlinked sub-folders (a library often links
    its parts in) but enters each real folder once, so a symlink loop (``a -> .``) ends;
    hidden entries and the folder ``skip`` (OUTDIR: a batch's own outputs are no inputs)
    are left out. Yields ``(here, dirs, files)``; a caller may prune ``dirs`` in place.

    A folder that cannot be listed (``os.walk`` passes over it in silence: a batch would
    miss its files and say nothing) is appended to ``skipped`` as ``(path, reason)``, or
    without that list raises ``BatchUsageError``.
    """
    seen = set()
    skip = None if skip is None else _identity(skip)

    def unreadable(exc):
        if skipped is None:
            raise BatchUsageError(f"{exc.filename}: cannot read this folder "
                                  f"({exc.strerror or exc}); its files would be left out")
        skipped.append((exc.filename, exc.strerror or str(exc)))

    for root, dirs, files in os.walk(folder, followlinks=True, onerror=unreadable):
        me = _identity(root)
        if me in seen or (skip is not None and me == skip):
            dirs[:] = []
            continue
        seen.add(me)
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        yield Path(root), dirs, [f for f in files if not f.startswith(".")]


def _identity(path):
    """``(device, inode)`` of a folder, the same through every symlink to it."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_dev, st.st_ino


def _search(folder, suffixes, take_rig_folders, skip=None, skipped=None):
    """Files under ``folder`` whose suffix is one of ``suffixes`` (hidden entries, ``skip``
    and rig folders' insides skipped; rig folders themselves when ``take_rig_folders``)."""
    found = []
    for here, dirs, files in _walk(folder, skip, skipped):
        keep = []
        for d in dirs:
            if _is_rig_folder(here / d):
                if take_rig_folders:
                    found.append(here / d)
                continue
            keep.append(d)
        dirs[:] = keep
        found += [here / f for f in files if Path(f).suffix.lower() in suffixes]
    return found


def _match(parts, pattern):
    """Whether the path components ``parts`` match the glob components ``pattern`` (``**``:
    any number of components, none included)."""
    if not pattern:
        return not parts
    if pattern[0] == "**":
        return _match(parts, pattern[1:]) or bool(parts) and _match(parts[1:], pattern)
    return bool(parts) and fnmatch.fnmatchcase(parts[0], pattern[0]) \
        and _match(parts[1:], pattern[1:])


def _glob(text, skip=None, skipped=None):
    """The paths ``text`` matches. ``glob``'s own ``**`` follows symlinks without end (two
    links to ``.`` make 2**40 paths), so a recursive pattern walks with :func:`_walk`."""
    text = os.path.expanduser(text)
    parts = Path(text).parts
    if "**" not in parts:
        yield from (Path(p) for p in glob.iglob(text))
        return
    first = next(i for i, part in enumerate(parts) if glob.has_magic(part))
    root, pattern = Path(*parts[:first]) if first else Path("."), parts[first:]
    for here, dirs, files in _walk(root, skip, skipped):
        rel = here.relative_to(root).parts if here != root else ()
        for name in dirs + files:
            if _match(rel + (name,), pattern):
                yield here / name


def _resolve(path):
    """``path`` made absolute with its symlinks resolved; a symlink loop (which ``resolve``
    raises for) stays as it is, to fail its task with the system's own words."""
    try:
        return path.resolve()
    except (RuntimeError, OSError):
        return Path(os.path.abspath(path))


def _inside(path, folder):
    """Whether ``path`` is ``folder`` or lies below it."""
    return folder is not None and (path == folder or folder in path.parents)


def expand_inputs(job, inputs, outdir=None, skipped=None):
    """Every path a batch of ``job`` reads from ``inputs``, sorted and without repeats.

    Parameters
    ----------
    job : str
        A key of :data:`JOB_SUFFIXES`.
    inputs : list of str or os.PathLike
        Files (taken as they are, whatever their suffix: a wrong one is that task's error),
        folders (searched for the job's suffixes, symlinked sub-folders included; a rig
        folder is one input of the rig jobs), globs (``**`` searches below a folder), and for
        the rig jobs bundled names (``humanoid``, ``quadruped``).
    outdir : Path, optional
        The batch's OUTDIR: a folder search or a pattern leaves it out (a second run must
        not take the first one's outputs for inputs); a file named on its own is kept.
    skipped : list, optional
        Where a sub-folder that cannot be listed goes, as ``(path, reason)`` (``lost+found``
        at the top of a volume); without it such a folder is a ``BatchUsageError``.

    Returns
    -------
    list[Path]
        Absolute paths (bundled names stay names).

    Raises
    ------
    BatchUsageError
        An input that exists nowhere and matches nothing, a folder that is OUTDIR, or no
        input at all.
    """
    suffixes = JOB_SUFFIXES[job]
    rigs = job in _RIG_JOBS
    own = None if outdir is None else _resolve(Path(outdir))
    out = set()
    for text in inputs:
        text = str(text)
        if not text.strip():   # Path("") is ".": an unset "$DIR" searched the working folder
            raise BatchUsageError(f"expected an input, got an empty name {text!r}")
        path = Path(text).expanduser()
        if rigs and text in BUNDLED and not path.exists():
            out.add(Path(text))
        elif _is_rig_folder(path) and rigs:
            out.add(_resolve(path))
        elif path.is_dir():
            if own is not None and _resolve(path) == own:
                raise BatchUsageError(f"{text}: expected inputs apart from OUTDIR, got OUTDIR "
                                      "itself (its outputs would be the next run's inputs)")
            found = _search(path, suffixes, rigs, skip=own, skipped=skipped)
            if not found:
                raise BatchUsageError(f"{text}: no {job} input in this folder (looked for "
                                      f"{', '.join(suffixes)})")
            out.update(_resolve(p) for p in found)
        elif path.exists():
            out.add(_resolve(path))
        elif glob.has_magic(text):
            found = [_resolve(p) for p in _glob(text, skip=own, skipped=skipped)
                     if p.is_file() or (rigs and _is_rig_folder(p))]
            found = [p for p in found if not _inside(p, own)]
            if not found:
                raise BatchUsageError(f"{text}: the pattern matches no file"
                                      + (" outside OUTDIR" if own is not None else ""))
            out.update(found)
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
            h.update(name_bytes(f.relative_to(path)) + b"\0")
        with open(f, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
    return "sha256:" + h.hexdigest()


def quick_stamp(source):
    """``[size, mtime_ns]`` of a file, the cheap check a resume makes before hashing again;
    None when it cannot be read. A folder: the summed size, the latest time and a digest of
    every file's relative name, size and time, since a renamed file (``clips/walk.json`` to
    ``clips/run.json``: a clip renamed) or one copied in with its old time keeps the sum and
    the latest time."""
    path = resolve_rig_path(str(source)) if str(source) in BUNDLED else Path(source)
    try:
        files = _files_of(path)
        stats = [f.stat() for f in files]
    except OSError:
        return None
    stamp = [sum(s.st_size for s in stats), max((s.st_mtime_ns for s in stats), default=0)]
    if path.is_dir():
        h = hashlib.sha1()
        for f, s in zip(files, stats):
            h.update(name_bytes(f.relative_to(path)) + f"\0{s.st_size}\0{s.st_mtime_ns}\0".encode())
        stamp.append(h.hexdigest()[:16])
    return stamp
