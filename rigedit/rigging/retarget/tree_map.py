"""A joint map between two skeletons of the same build found by the shape of their trees
(two quadrupeds with unrelated joint names), for when the names do not give one.

Both skeletons stand in their calibration poses (:class:`rigedit.rigging.retarget.limbs.
LegCalibration`). Their legs must agree: as many hanging from the hips and as many from
elsewhere (a humanoid's two legs do not make a quadruped's four); otherwise there is no map.
From the hips (paired), the tree is walked down in *runs*: from a paired joint, each child
starts a run that follows single children to the next branching joint or leaf. The runs of
two paired joints are paired greedily by the direction from the joint to the run's end,
expressed in each figure's body frame (left, up, forward), when the directions are within 60
degrees; the ends of paired runs pair, so do their first joints, the joints between pair by
fraction of length (as the humanoid spines do), and the walk goes on below the ends.
"""
from __future__ import annotations

import numpy as np

from .name_map import interior_map, name_pairs

__all__ = ["tree_map", "leg_map", "legs_agree", "MAX_ANGLE"]

MAX_ANGLE = 60.0


def legs_agree(src, tgt):
    """Whether two leg calibrations have as many legs hanging from the hips and as many
    hanging from elsewhere."""
    return src.leg_counts() == tgt.leg_counts()


def _runs(skeleton, j):
    """The runs below joint ``j``: lists from a child down single children to a branching
    joint or a leaf."""
    out = []
    for c in skeleton.children(j):
        run = [int(c)]
        while len(skeleton.children(run[-1])) == 1:
            run.append(int(skeleton.children(run[-1])[0]))
        out.append(run)
    return out


def _body_direction(cal, a, b):
    """Unit direction from joint ``a`` to joint ``b`` in the body frame (left, up, forward)."""
    d = cal.points[b] - cal.points[a]
    d = np.array([d @ cal.left, d @ cal.up, d @ cal.forward])
    n = np.linalg.norm(d)
    return d / n if n > 0 else d


def tree_map(src, tgt):
    """Source joint -> target joint names paired by the trees' shape.

    Parameters
    ----------
    src, tgt : LegCalibration

    Returns
    -------
    mapping : dict[str, str]
        Empty when the legs do not agree (:func:`legs_agree`).
    """
    if not legs_agree(src, tgt):
        return {}
    ssk, tsk = src.skeleton, tgt.skeleton
    pairs = [(src.hips, tgt.hips)]
    todo = [(src.hips, tgt.hips)]
    limit = np.cos(np.radians(MAX_ANGLE))
    while todo:
        s, t = todo.pop()
        s_runs, t_runs = _runs(ssk, s), _runs(tsk, t)
        if not s_runs or not t_runs:
            continue
        cos = np.array([[_body_direction(src, s, a[-1]) @ _body_direction(tgt, t, b[-1])
                         for b in t_runs] for a in s_runs])
        while cos.size and cos.max() > limit:
            i, k = np.unravel_index(np.argmax(cos), cos.shape)
            cos[i, :], cos[:, k] = -2.0, -2.0
            a, b = s_runs[i], t_runs[k]
            pairs.append((a[-1], b[-1]))
            if len(a) > 1 and len(b) > 1:
                pairs.append((a[0], b[0]))
                pairs += interior_map(a, src.points, b, tgt.points)
            todo.append((a[-1], b[-1]))
    return {ssk.names[a]: tsk.names[b] for a, b in pairs}


def leg_map(src, tgt):
    """The map between two skeletons calibrated by their legs: equal names when they reach
    the target's hips, else the trees' shape (:func:`tree_map`) completed by equal names."""
    ssk, tsk = src.skeleton, tgt.skeleton
    mapping = name_pairs(ssk, tsk)
    if tsk.names[tgt.hips] not in mapping.values():
        by_shape = tree_map(src, tgt)
        if by_shape:
            mapping = by_shape
            mapping.update(name_pairs(ssk, tsk, by_shape))
    return mapping
