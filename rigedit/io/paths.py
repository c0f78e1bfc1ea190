"""Checks on the paths rigedit reads: a regular file, readable, a sane name, or one error.

A FIFO would make ``open`` wait for a writer for ever and ``/dev/zero`` never ends, so every
reader asks :func:`regular_file` first and opens FIFOs never.
"""
from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

from ..errors import RigFileError

__all__ = ["regular_file", "read_bytes", "list_folder", "os_problem", "what_is",
           "MAX_FILE_BYTES"]

#: Larger files are refused before they are read (a mesh of 10 million triangles as OBJ is
#: about 1 GB).
MAX_FILE_BYTES = 4 * 2**30

_KINDS = [(stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISSOCK, "a socket")]


def os_problem(exc):
    """One phrase for an ``OSError``: what a user can act on, without Python's decoration."""
    if isinstance(exc, FileNotFoundError):
        return "file not found"
    if isinstance(exc, PermissionError):
        return "permission denied"
    if exc.errno == errno.ENAMETOOLONG:
        return "file name too long"
    if exc.errno == errno.ELOOP:
        return "too many levels of symbolic links"
    if isinstance(exc, IsADirectoryError):
        return "expected a file, got a folder"
    return f"cannot read: {exc.strerror or exc}"


def what_is(path):
    """``"a folder"``, ``"a file"`` (regular), another kind (``"a FIFO (named pipe)"``, ...)
    or None when nothing is there; a name the system refuses (too long, in a folder that
    cannot be searched) is a ``RigFileError`` naming it."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the name
        raise RigFileError(path, os_problem(exc) if isinstance(exc, OSError)
                           else "expected a file name, got one with a NUL byte") from None
    if stat.S_ISREG(mode):
        return "a file"
    return next((k for test, k in _KINDS if test(mode)), "not a regular file")


def regular_file(path, max_bytes=MAX_FILE_BYTES):
    """``os.stat`` of ``path`` when it is a regular file that is not too large.

    Raises
    ------
    RigFileError
        Missing, not a regular file (a folder, a FIFO, a device), unreadable name, too large.
    """
    kind = what_is(path)
    if kind is None:
        raise RigFileError(path, "file not found")
    if kind != "a file":
        raise RigFileError(path, f"expected a regular file, got {kind}")
    st = os.stat(path)
    if st.st_size > max_bytes:
        raise RigFileError(path, f"expected a file of at most {max_bytes} bytes, got "
                                 f"{st.st_size} bytes")
    return st


def read_bytes(path, max_bytes=MAX_FILE_BYTES):
    """The whole content of a regular file; ``RigFileError`` naming it otherwise."""
    regular_file(path, max_bytes)
    try:
        # O_NONBLOCK: should the path have become a FIFO since the check, open returns at once.
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as fh:
            st = os.fstat(fh.fileno())
            if not stat.S_ISREG(st.st_mode):
                raise RigFileError(path, "expected a regular file")
            # read(n) allocates n bytes up front: ask for the size the file has (one more
            # byte tells a file that grew past the bound).
            data = fh.read(min(st.st_size, max_bytes) + 1)
    except OSError as exc:
        raise RigFileError(path, os_problem(exc)) from None
    if len(data) > max_bytes:
        raise RigFileError(path, f"expected a file of at most {max_bytes} bytes")
    return data


def list_folder(folder):
    """Entries of a folder, sorted; ``RigFileError`` when it cannot be listed."""
    try:
        return sorted(Path(folder).iterdir())
    except OSError as exc:
        raise RigFileError(folder, os_problem(exc)) from None
