"""Every editing command of the editor, in one place for scripts and views.

The Document's own methods (:class:`~rigedit.editor.document.Document`) hold the core: mode
(``set_mode``), selection (``select``), time and sampling (``set_time``, ``sample``,
``set_current_clip``), pose edits (``set_pose``, ``set_joint_euler``, ``set_joint_translation``,
``set_joint_scale``, ``reset_joint``, ``reset_pose``, ``mirror_pose``, ``begin_drag`` /
``drag_euler`` / ``end_drag``), rest and weight edits (``push_rest_edit``, ``set_weights``)
and history (``undo``, ``redo``); the morph weights shown are ``document.morph``. The rest
are functions taking the document, gathered here::

    from rigedit.editor import commands as cmd

    doc = cmd.open_document("quadruped")
    drag = cmd.PoseDrag(doc, "head")       # a joint pulled by IK, one undo step
    drag.step(target); drag.end()
    cmd.set_key(doc, ["head"], t=0.5)
    cmd.save_rig_folder(doc, "out/quadruped")

Each change goes through the undo stack where a user expects undo, and is announced with a
typed event (:mod:`rigedit.editor.events`).
"""
from __future__ import annotations

from .clip_commands import (add_clip, delete_clip, duplicate_clip, new_clip, rename_clip,
                            set_duration, unique_clip_name)
from .deform import set_joint_deform
from .drag import PoseDrag
from .autorig import open_autorigged
from .files import (export_pose, export_rig, export_skeleton, load_weights, open_document,
                    open_rig, save_rig_folder, save_weights)
from .key_commands import (KeyDrag, copy_keys, delete_key, key_near, move_keys, paste_keys,
                           set_interpolation, set_key)
from .morphs import WeightDrag, delete_weight_key, key_weight, set_weight
from .recompute import RecomputeWeights, recompute_weights
from .weight_stroke import WeightStroke

__all__ = ["open_document", "open_rig", "save_rig_folder", "export_rig", "export_pose",
           "export_skeleton", "load_weights", "save_weights", "open_autorigged", "PoseDrag",
           "set_key", "key_near", "delete_key", "move_keys", "KeyDrag", "copy_keys", "paste_keys",
           "set_interpolation", "new_clip", "add_clip", "rename_clip", "duplicate_clip",
           "delete_clip", "set_duration", "unique_clip_name", "WeightStroke",
           "set_joint_deform", "RecomputeWeights", "recompute_weights", "set_weight",
           "WeightDrag", "key_weight", "delete_weight_key"]
