"""Motion retargeting: a clip from one skeleton onto another (numpy + scipy).

:mod:`.pipeline` (:func:`retarget`), joint maps (:mod:`.name_map`, :mod:`.tree_map`),
calibration (:mod:`.calibrate`, :mod:`.limbs`, :mod:`.facing`), bone directions
(:mod:`.transfer`, :mod:`.chains`, :mod:`.pitch`, :mod:`.bare`), feet (:mod:`.contacts`,
:mod:`.soles`), baking keys (:mod:`.bake`) and measures (:mod:`.measure`).
"""
from .name_map import auto_map, find_slots, load_map, save_map
from .pipeline import RetargetResult, retarget, retarget_result

__all__ = ["retarget", "retarget_result", "RetargetResult", "auto_map", "find_slots", "load_map",
           "save_map"]
