"""Crash-safe writes: a temporary file beside the target, then an atomic rename."""
from __future__ import annotations

import contextlib
import json
import os
import tempfile
from pathlib import Path

__all__ = ["atomic_write", "write_json", "temp_beside"]


def temp_beside(path, suffix=None):
    """Create an empty temporary file next to ``path`` (same folder, so a rename is atomic)
    with the permissions a new file would get (``mkstemp`` makes it 0600), or the target's
    own when it exists. Returns ``(fd, tmp_path)``."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix or ".tmp", dir=path.parent)
    try:
        mode = path.stat().st_mode & 0o777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    os.chmod(tmp, mode)
    return fd, tmp


@contextlib.contextmanager
def atomic_write(path, mode="w", suffix=None):
    """Open a temporary file next to ``path``; on success rename it over ``path``.

    A crash or an exception leaves ``path`` as it was and removes the temporary file. Yields
    the open file object (text mode by default, ``mode="wb"`` for bytes). ``suffix`` gives the
    temporary name an extension, for writers that choose the format by it (``np.savez``).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = temp_beside(path, suffix)
    try:
        with os.fdopen(fd, mode, **({} if "b" in mode else {"encoding": "utf-8"})) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def write_json(path, data, indent=1):
    """Write JSON atomically."""
    with atomic_write(path) as fh:
        json.dump(data, fh, indent=indent)
        fh.write("\n")
