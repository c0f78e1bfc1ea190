"""The bundled characters: their names, their folder, and which paths are read-only.

Here rather than in the package root so that io (which resolves bundled names and refuses to
save over them) imports nothing above it; ``rigedit`` re-exports these names.
"""
from __future__ import annotations

import importlib.resources
import os
from pathlib import Path

__all__ = ["BUNDLED", "ASSETS_DIR", "resolve_rig_path", "is_bundled"]

#: The rigedit package folder.
_PACKAGE = Path(__file__).resolve().parent.parent

#: Names accepted wherever a rig is asked for; the first is the default.
BUNDLED = ("quadruped", "humanoid")


def _assets_dir():
    """The folder of the bundled characters: ``$RIGEDIT_ASSETS`` when set, else the data package
    ``rigedit.assets`` through ``importlib.resources`` (the repository's top-level ``assets/``
    folder: copied into the package by a normal install, mapped onto ``assets/`` by an editable
    one), else the ``assets/`` folder beside the package in a plain checkout."""
    if os.environ.get("RIGEDIT_ASSETS"):
        return Path(os.environ["RIGEDIT_ASSETS"])
    try:
        location = Path(str(importlib.resources.files("rigedit.assets")))
    except ImportError:  # a checkout on sys.path without an install of the package
        location = None
    if location is not None and (location / BUNDLED[0]).is_dir():
        return location
    return _PACKAGE.parent / "assets"


#: Where the bundled characters live (see ``_assets_dir``).
ASSETS_DIR = _assets_dir()


def resolve_rig_path(rig=None):
    """Path of a rig folder from a bundled name, a path, or None (the default character)."""
    if rig is None:
        rig = BUNDLED[0]
    if str(rig) in BUNDLED and not Path(rig).exists():
        return ASSETS_DIR / str(rig)
    return Path(rig)


def is_bundled(path):
    """True when ``path`` is (inside) a bundled character or the installed package: those are
    read-only for the editor (File > Save asks for a new place)."""
    roots = {Path(ASSETS_DIR).resolve(), _PACKAGE, _PACKAGE.parent / "assets"}
    try:
        path = Path(path).resolve()
    except (OSError, ValueError):   # a name the system refuses: no place of the package
        return False
    return any(path == root or root in path.parents for root in roots)
