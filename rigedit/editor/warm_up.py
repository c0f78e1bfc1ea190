"""Work the editor starts in the background once its window is up, so that it neither delays
the first frame nor happens during the first drag."""
from __future__ import annotations

from ..model import skinning_kernels

__all__ = ["start_loading_kernels"]


def start_loading_kernels():
    """Load the compiled skinning kernels (from numba's disk cache, compiling them the first
    time) in a background thread, once per process; returns at once
    (:func:`rigedit.model.skinning_kernels.start_loading`)."""
    skinning_kernels.start_loading()
