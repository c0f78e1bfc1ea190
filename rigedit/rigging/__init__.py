"""Rigging above the model: joint mapping and motion retargeting (numpy + scipy).

- :mod:`.name_map`: canonical humanoid slots from names and tree structure, joint maps.
- :mod:`.limbs`: legs of any skeleton found by structure (quadrupeds and others).
- :mod:`.retarget`: transfer a clip between skeletons with different rest poses and sizes.
- :mod:`.contacts`: foot contacts in the source, leg IK clean-up on the target.
"""
from __future__ import annotations

from .name_map import auto_map, find_slots, load_map, save_map
from .retarget import RetargetResult, retarget, retarget_result

__all__ = ["retarget", "retarget_result", "RetargetResult", "auto_map", "find_slots", "load_map", "save_map"]
