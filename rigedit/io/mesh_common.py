"""What the mesh readers share: fan triangulation, and calling a third-party reader quietly.

Used by :mod:`rigedit.io.mesh` (OBJ, meshio formats) and :mod:`rigedit.io.vtp`, which
:mod:`rigedit.io.mesh` dispatches to.
"""
from __future__ import annotations

import contextlib
import io
import warnings

import numpy as np

from ..errors import RigFileError

__all__ = ["triangulate", "third_party_read"]


def triangulate(polygons):
    """Fan-triangulate a list of polygons (index lists) into (F, 3) int64."""
    tris = [(p[0], p[i], p[i + 1]) for p in polygons for i in range(1, len(p) - 1)]
    return np.array(tris, dtype=np.int64).reshape(-1, 3)


def third_party_read(path, read):
    """Call a third-party reader so that nothing it does reaches the user: its prints go to a
    buffer, a ``sys.exit`` or any exception becomes a ``RigFileError`` naming the file."""
    out = io.StringIO()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out), \
                warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return read()
    except RigFileError:
        raise
    except (Exception, SystemExit) as exc:  # meshio calls sys.exit(1) on an unreadable file
        said = " ".join(out.getvalue().split())
        detail = str(exc) if not isinstance(exc, SystemExit) else ""
        detail = " ".join((detail or said or type(exc).__name__).split())
        raise RigFileError(path, f"cannot read mesh: {detail[:200]}") from None
