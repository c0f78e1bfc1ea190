"""Rigging above the model, in two halves: :mod:`.autorig` (any mesh to an animated
character) and :mod:`.retarget` (a clip from one skeleton onto another). numpy + scipy.

The halves are subpackages of ``rigging`` rather than top-level packages because
``rigedit.autorig`` and ``rigedit.retarget`` are the API's functions (a subpackage of the same
name would replace them on the package). The names below are the public ones this package has
always exported.
"""
from __future__ import annotations

from .retarget.name_map import auto_map, find_slots, load_map, save_map
from .retarget.pipeline import RetargetResult, retarget, retarget_result

__all__ = ["retarget", "retarget_result", "RetargetResult", "auto_map", "find_slots", "load_map",
           "save_map"]
