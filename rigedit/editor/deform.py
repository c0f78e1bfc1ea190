"""The deform flag of a joint (whether it takes skin weight), set as one undo step.

:func:`skeleton_with_deform` makes the new skeleton; :func:`set_joint_deform` records the
change on the document. The binding is unchanged until the weights are recomputed
(:mod:`.recompute`). Pure numpy.
"""
from __future__ import annotations

import dataclasses

__all__ = ["skeleton_with_deform", "set_joint_deform"]


def skeleton_with_deform(skeleton, joint, deform):
    """A copy of ``skeleton`` where ``joint`` does (True) or does not (False) take skin
    weight at the next weights computation."""
    flags = skeleton.deform.copy()
    flags[joint] = bool(deform)
    return dataclasses.replace(skeleton, deform=flags)


def set_joint_deform(document, joint, deform):
    """Set a joint's deform flag as one undo step (a rest edit: the binding is unchanged until
    the weights are recomputed). Returns False when the flag already had that value."""
    sk = document.skeleton
    j = sk.joint_index(joint)
    if bool(sk.deform[j]) == bool(deform):
        return False
    before = document.rest_state()
    after = (skeleton_with_deform(sk, j, deform), before[1], before[2])
    label = f"{'Deform' if deform else 'No deform'} {sk.names[j]}"
    document.push_rest_edit(label, before, after)
    return True
