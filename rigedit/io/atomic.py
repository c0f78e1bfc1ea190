"""Crash-safe writes: a temporary file beside the target, then an atomic rename."""
from __future__ import annotations

import contextlib
import json
import os
import tempfile
from pathlib import Path

__all__ = ["atomic_write", "write_json"]


@contextlib.contextmanager
def atomic_write(path, mode="w", suffix=None):
    """Open a temporary file next to ``path``; on success rename it over ``path``.

    A crash or an exception leaves ``path`` as it was and removes the temporary file. Yields
    the open file object (text mode by default, ``mode="wb"`` for bytes). ``suffix`` gives the
    temporary name an extension, for writers that choose the format by it (``np.savez``).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix or ".tmp", dir=path.parent)
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
