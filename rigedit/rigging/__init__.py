"""Rigging above the model: auto-rigging, joint mapping and motion retargeting (numpy +
scipy).

- :mod:`.autorig`: any mesh to an animated character (:mod:`.mesh_check`, :mod:`.orient`
  with :mod:`.mirror` and :mod:`.ground`, :mod:`.templates`, then
  :mod:`rigedit.embedding`); :mod:`.autorig_command` is the CLI's part.
- :mod:`.name_map`: canonical humanoid slots from names and tree structure, joint maps.
- :mod:`.limbs`: legs of any skeleton found by structure (quadrupeds and others);
  :mod:`.tree_map`: a joint map from the trees' shape.
- :mod:`.retarget`: transfer a clip between skeletons with different rest poses and sizes
  (:mod:`.calibrate`, :mod:`.transfer`, :mod:`.chains`, :mod:`.pitch`, :mod:`.bake`);
  :mod:`.measure`: its quality measures; :mod:`.command`: the CLI's part.
- :mod:`.contacts`: foot contacts in the source, leg IK clean-up on the target.
"""
from __future__ import annotations

from .name_map import auto_map, find_slots, load_map, save_map
from .retarget import RetargetResult, retarget, retarget_result

__all__ = ["retarget", "retarget_result", "RetargetResult", "auto_map", "find_slots", "load_map",
           "save_map"]
