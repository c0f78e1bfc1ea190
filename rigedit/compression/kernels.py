"""The package's compiled kernels (numba), imported on first use.

Nothing imports numba at module import: :func:`load` imports a kernel module (which imports
numba and compiles, or loads from numba's on-disk cache, ``cache=True``) the first time it is
asked for, and None when numba is missing or ``RIGEDIT_NO_NUMBA=1`` (the numpy code is then
used: it is the reference the tests compare the kernels with)."""
from __future__ import annotations

import importlib
import os

__all__ = ["load", "loaded"]

_MODULES = {}


def load(name):
    """The kernel module ``rigedit.compression.<name>`` or None (see the module notes)."""
    if name not in _MODULES:
        module = None
        if os.environ.get("RIGEDIT_NO_NUMBA", "") in ("", "0"):
            try:
                module = importlib.import_module(f"{__package__}.{name}")
            except ImportError:
                module = None
        _MODULES[name] = module
    return _MODULES[name]


def loaded(name):
    """True once :func:`load` has imported kernel module ``name``."""
    return _MODULES.get(name) is not None
