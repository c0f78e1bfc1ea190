"""Where a biped's legs meet its trunk: the height of the thigh joints.

The search puts the reduced root (the hips) on a medial sphere centre in the trunk, and the
thigh joints hang from it at the template's offset. On a character whose trunk is deep
against its legs (a big belly, a short-legged cartoon), that centre sits high in the belly
and the thighs with it, and the knees end up at the crotch. What the mesh does say is where
the legs part: scanning up the middle plane between the two legs, the first point inside
the mesh is the crotch. The thigh joints (the heads of the femurs) sit above it by the
template's own proportion: their height above the crotch over the crotch's height above the
ankles, measured on the template's mesh when there is one (0.22 on the bundled humanoid;
CesiumMan's artist put them 3% below instead), else ``LEG_TOP``.

Only for two legs (a biped): a quadruped's hind legs part at its belly while its hip joints
sit up near its back, so the rule does not hold there and nothing is changed.
"""
from __future__ import annotations

import numpy as np

from .fit import FEET

__all__ = ["leg_top_heights", "lower_leg_tops", "template_leg_top", "LEG_TOP"]

#: Thigh joints' height above the crotch over the crotch's height above the ankles, for a
#: template without a mesh: the bundled humanoid's (measured on its mesh).
LEG_TOP = 0.22

#: A thigh height found further than this fraction of the leg's present length from where
#: the thighs are is not trusted (legs joined by a robe, a mesh open between the legs): the
#: template's stays.
MAX_MOVE = 0.5


def _legs(template):
    """The two leg chains (reduced indices) of a biped template, or None."""
    rest, joints = template.rest, template.joints
    live = joints[~template.carried[joints]]
    span = np.ptp(rest[live, 1]) if len(live) else 0.0
    leaves = [r for r in range(1, len(joints)) if not np.any(template.parent == r)]
    feet = [r for r in leaves if rest[joints[r], 1] - template.floor < FEET * span
            and len(template.chains[r]) >= 3 and not template.optional[r]]
    if len(feet) != 2:
        return None
    a, b = feet
    if template.mirror[a] != b or template.parent[a] != template.parent[b]:
        return None
    return feet


def _ends(template, positions):
    """Thigh and foot joints of a biped's legs and their hips, or None."""
    legs = _legs(template)
    if legs is None:
        return None
    tops = [template.chains[r][1] for r in legs]
    feet = [template.joints[r] for r in legs]
    hips = template.joints[template.parent[legs[0]]]
    if not np.all(np.isfinite(positions[tops + feet + [hips]])):
        return None
    return tops, feet, hips


def template_leg_top(template, vertices, faces):
    """The template's thigh height above its crotch over the crotch's height above its
    ankles, from its mesh (``LEG_TOP`` when it is not a biped or shows no crotch).

    The crotch is the lowest point of the mesh straight above the middle of the two ankles
    (the template stands at rest, legs hanging).

    Parameters
    ----------
    template : ReducedTemplate
    vertices : (V, 3) float64
        The template's mesh at its rest pose, in the frame of ``template.rest``.
    faces : (F, 3) int
    """
    ends = _ends(template, template.rest)
    if ends is None:
        return LEG_TOP
    tops, feet, _ = ends
    top, foot = template.rest[tops].mean(axis=0), template.rest[feet].mean(axis=0)
    tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces)]
    # the vertical line through (foot x, foot z): barycentric coordinates in the xz plane
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    w = np.array([foot[0], 0.0, foot[2]]) - tri[:, 0]
    det = e1[:, 0] * e2[:, 2] - e1[:, 2] * e2[:, 0]
    ok = np.abs(det) > 1e-15
    det = np.where(ok, det, 1.0)
    u = (w[:, 0] * e2[:, 2] - w[:, 2] * e2[:, 0]) / det
    v = (e1[:, 0] * w[:, 2] - e1[:, 2] * w[:, 0]) / det
    hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1)
    y = tri[hit, 0, 1] + u[hit] * e1[hit, 1] + v[hit] * e2[hit, 1]
    y = y[(y > foot[1]) & (y < top[1] + (top[1] - foot[1]))]
    if not len(y) or y.min() - foot[1] <= 0:
        return LEG_TOP
    crotch = float(y.min())
    return (top[1] - crotch) / (crotch - foot[1])


def leg_top_heights(field, template, positions, plane, above=LEG_TOP):
    """Heights of a biped's thigh joints: above the crotch by ``above`` times the crotch's
    height above the ankles.

    Parameters
    ----------
    field : DistanceField
    template : ReducedTemplate
    positions : (J, 3) float64
        Every template joint as placed from the embedded reduced joints (NaN where not).
    plane : float
        The mesh's middle plane, x = plane.
    above : float
        From :func:`template_leg_top`.

    Returns
    -------
    dict[int, float]
        Template index of each thigh joint -> its height; empty when the template is not a
        biped, the legs are not both placed, or the mesh shows no crotch where one could be.
    """
    ends = _ends(template, positions)
    if ends is None:
        return {}
    tops, feet, hips = ends
    foot = positions[feet].mean(axis=0)
    top = positions[tops].mean(axis=0)
    length = top[1] - foot[1]
    if length <= 0:
        return {}
    # up the middle plane, from the feet to above the hips, on the line between the legs
    ys = np.arange(foot[1], max(positions[hips, 1], top[1]) + MAX_MOVE * length, 0.5 * field.h)
    t = (ys - foot[1]) / length
    line = np.c_[np.full_like(ys, plane), ys, foot[2] + t * (top[2] - foot[2])]
    inside = field(line) > 0
    if inside[0] or not inside.any():
        return {}  # legs joined at the feet, or never meeting: no crotch to go by
    crotch = ys[int(np.argmax(inside))]
    # the template's proportion (of the leg below the crotch, which a crouch or a stance
    # shortens alike) rather than its scaled offset: a cartoon's short legs keep short thighs
    y = crotch + above * (crotch - foot[1])
    if abs(y - top[1]) > MAX_MOVE * length:
        return {}
    return {j: y for j in tops}


def lower_leg_tops(template, positions, heights):
    """Move a biped's thighs to ``heights``, the hips and the chains they join with them.

    Each thigh goes to its height; the joints inside its leg move by the thigh's shift times
    the template's fraction of the leg's length still below them (the knee of an even leg
    half as far; the foot stays), so they divide the leg in the template's proportions. The
    hips move with the thighs' mean shift, and the inner joints of the hips' other chains
    (the spine) likewise by the fraction of their chain still ahead of them (the chain's far
    end stays).

    Parameters
    ----------
    template : ReducedTemplate
    positions : (J, 3) float64
    heights : dict[int, float]
        From :func:`leg_top_heights`.

    Returns
    -------
    (J, 3) float64
    """
    out = np.array(positions, dtype=np.float64)
    if not heights:
        return out
    shift = {}
    for r in range(1, len(template.joints)):
        chain = template.chains[r]
        if len(chain) > 2 and chain[1] in heights:
            shift[r] = heights[chain[1]] - out[chain[1], 1]
    if not shift:
        return out
    hips_r = template.parent[next(iter(shift))]
    hips = template.joints[hips_r]
    d_hips = float(np.mean(list(shift.values())))
    rest = template.rest
    for r in np.flatnonzero(template.parent == hips_r):
        chain = template.chains[r]
        bones = np.linalg.norm(np.diff(rest[chain], axis=0), axis=1)
        if r in shift:
            # from the thigh (fraction 0) to the foot (1)
            run = np.concatenate([[0.0], np.cumsum(bones[1:])]) / max(bones[1:].sum(), 1e-12)
            for j, s in zip(chain[1:-1], run[:-1]):
                out[j, 1] += (1.0 - s) * shift[r]
        else:
            run = np.cumsum(bones) / max(bones.sum(), 1e-12)
            for j, s in zip(chain[1:-1], run[:-1]):
                out[j, 1] += (1.0 - s) * d_hips
    out[hips, 1] += d_hips
    return out
