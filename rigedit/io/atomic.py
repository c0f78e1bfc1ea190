"""Crash-safe writes: a temporary file beside the target, then an atomic rename.

Errors name the user's file, never the hidden temporary one, and a missing folder is an error
(:func:`check_output_folder`), not created on the fly: a typo in an output path should not
leave new folders around. A write that fails (disk full, permission denied, a read-only file
system) is one :class:`~rigedit.errors.RigWriteError` naming the user's path
(:func:`write_error`, :func:`writing`), and the temporary file is removed.
"""
from __future__ import annotations

import contextlib
import json
import os
import tempfile
from pathlib import Path

from ..errors import RigFileError, RigWriteError

__all__ = ["atomic_write", "write_json", "temp_beside", "check_output_folder",
           "fsync_folder", "naming_target", "write_error", "writing", "remove_stale_temps"]

def write_error(exc, path):
    """``exc`` (an ``OSError`` of a write) as the :class:`RigWriteError` naming ``path``, the
    user's file or folder; other exceptions are returned as they are."""
    if isinstance(exc, RigFileError) or not isinstance(exc, OSError):
        return exc
    # the system's own words ("No space left on device", "Read-only file system")
    problem = exc.strerror or str(exc) or type(exc).__name__
    return RigWriteError(path, f"cannot write: {problem}", exc.errno, exc.strerror or str(exc))


@contextlib.contextmanager
def writing(path):
    """Turn an ``OSError`` raised in the block into :func:`write_error` naming ``path``."""
    try:
        yield
    except OSError as exc:
        new = write_error(exc, path)
        if new is exc:
            raise
        raise new from None


def check_output_folder(path):
    """``RigFileError`` naming ``path`` unless the folder it goes into exists."""
    path = Path(path)
    parent = path.parent
    if not parent.is_dir():
        raise RigFileError(path, f"expected an existing folder to write into, got "
                                 f"{'a file' if parent.exists() else 'no folder'} at {parent}")


def fsync_folder(folder):
    """Make renames and deletions in ``folder`` durable (a power cut after a save keeps
    them); a no-op where folders cannot be opened (Windows)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def naming_target(exc, tmp, path):
    """``exc`` as the same OSError naming ``path`` where it named the temporary file."""
    if isinstance(exc, OSError) and exc.filename in (str(tmp), tmp):
        new = type(exc)(exc.errno, exc.strerror, str(path))
        new.__suppress_context__ = True
        return new
    return exc


def _pid_prefix(path, pid):
    return f".{path.name}.pid{pid}-"


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:   # another user's process: alive
        return True
    return True


def remove_stale_temps(path, suffix=None):
    """Delete the temporary files that :func:`temp_beside` (``tagged=True``) made for
    ``path`` in processes that are gone (killed with SIGKILL before their clean-up ran).
    Those of running processes, and any other file, are left alone.

    Returns
    -------
    list[Path]
        The files removed.
    """
    path = Path(path)
    removed = []
    head = f".{path.name}.pid"
    try:
        entries = list(os.scandir(path.parent))
    except OSError:
        return removed
    for entry in entries:
        name = entry.name
        if not (name.startswith(head) and name.endswith(suffix or ".tmp")):
            continue
        pid = name[len(head):].split("-", 1)[0]
        if pid.isascii() and pid.isdigit() and int(pid) != os.getpid() \
                and not _alive(int(pid)) and entry.is_file(follow_symlinks=False):
            with contextlib.suppress(OSError):
                os.unlink(entry.path)
                removed.append(Path(entry.path))
    return removed


def temp_beside(path, suffix=None, tagged=False):
    """Create an empty temporary file next to ``path`` (same folder, so a rename is atomic)
    with the permissions a new file would get (``mkstemp`` makes it 0600), or the target's
    own when it exists. Returns ``(fd, tmp_path)``. ``tagged``: the name carries this
    process's id, so that a later run can tell a stale one (:func:`remove_stale_temps`)."""
    path = Path(path)
    check_output_folder(path)
    prefix = _pid_prefix(path, os.getpid()) if tagged else f".{path.name}."
    try:
        fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=suffix or ".tmp",
                                   dir=path.parent)
    except OSError as exc:  # say which file could not be written, not the temporary name
        raise write_error(exc, path) from None
    try:
        try:
            mode = path.stat().st_mode & 0o777
        except OSError:
            umask = os.umask(0)
            os.umask(umask)
            mode = 0o666 & ~umask
        os.chmod(tmp, mode)
    except BaseException:   # an interrupt here must not leave the empty file behind
        os.close(fd)
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return fd, tmp


@contextlib.contextmanager
def atomic_write(path, mode="w", suffix=None):
    """Open a temporary file next to ``path``; on success rename it over ``path``.

    A crash or an exception leaves ``path`` as it was and removes the temporary file. Yields
    the open file object (text mode by default, ``mode="wb"`` for bytes). ``suffix`` gives the
    temporary name an extension, for writers that choose the format by it (``np.savez``).
    The folder must exist (``RigFileError`` naming ``path`` otherwise).
    """
    path = Path(path)
    fd, tmp = temp_beside(path, suffix)
    try:
        with os.fdopen(fd, mode, **({} if "b" in mode else {"encoding": "utf-8"})) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        new = write_error(exc, path)
        if new is exc:
            raise
        raise new from None


def write_json(path, data, indent=1):
    """Write JSON atomically."""
    with atomic_write(path) as fh:
        json.dump(data, fh, indent=indent)
        fh.write("\n")
