"""Would a rigger sign this embedding off? The checks run after it (issue 17, section 1).

An embedding's cost says how well the template's bones fit the medial graph; it does not
say that the arms are in the arms. Ears as long as short arms, a head as big as the chest:
the cheapest fit may put the arms in the ears or the hips at the chin, at a lower cost than
a right rig of another mesh. So, as a rigger would, :func:`check_embedding` looks at the
result itself, in rigedit's frame (+Y up, facing +Z, the mirror plane x = const):

* **limb** -- each paired limb chain of the template (arms, legs) lies in a part of the
  mesh that ends, and narrows on its way there (:mod:`.limb_check`);
* **upright**, **mirror**, **inside**, **lengths** -- the hips low and the head above the
  shoulders, left and right joints mirror images, the bones inside the mesh, the chains in
  the template's proportions (:mod:`.shape_checks`).

Each failed check gives one line (the reason) and the joints in doubt; the margin to the
best alternative embedding (another orientation) is the caller's to add
(:mod:`.autorig`). Pure numpy/scipy.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...embedding.fit import FEET
# the checks' limits are importable from here, as before the checks were split off
from .limb_check import BULGE, CUT_AT, LIMB_VOLUME, SECTION, limb_check
from .shape_checks import (HIPS_HIGH, MIRROR_TOLERANCE, OUT_CELLS, OUTSIDE_SHARE, STRETCH,
                           inside_check, length_check, mirror_check, upright_check)

__all__ = ["Confidence", "check_embedding", "fit_score", "limb_roles", "LIMB_VOLUME",
           "HIPS_HIGH", "MIRROR_TOLERANCE", "OUTSIDE_SHARE", "STRETCH"]


@dataclass
class Confidence:
    """The checks' outcome.

    Attributes
    ----------
    sure : bool
        Every check passed.
    reasons : list[str]
        One line per failed check.
    doubtful : list[str]
        Joints in doubt (template names), for the editor to select.
    failed : list[str]
        The failed checks' names (``limb``, ``upright``, ``mirror``, ``inside``, ``lengths``).
    measures : dict[str, float]
        The worst value of each check, against its limit (for reports and tuning).
    """

    sure: bool = True
    reasons: list = field(default_factory=list)
    doubtful: list = field(default_factory=list)
    failed: list = field(default_factory=list)
    measures: dict = field(default_factory=dict)

    def fail(self, check, reason, joints=()):
        self.sure = False
        if check not in self.failed:
            self.failed.append(check)
        self.reasons.append(reason)
        for j in joints:
            if j not in self.doubtful:
                self.doubtful.append(j)


def limb_roles(reduced):
    """The template's limbs, from its reduced skeleton.

    Parameters
    ----------
    reduced : ReducedTemplate

    Returns
    -------
    dict
        ``legs``, ``arms``: reduced leaves with a mirror partner (not optional), legs
        standing on the ground; ``head``: the reduced leaf on the middle plane highest in
        the rest (None when there is none).
    """
    parent = reduced.parent
    rest = reduced.rest[reduced.joints]
    leaves = [r for r in range(1, len(parent)) if not (parent == r).any()]
    span = max(float(np.ptp(reduced.rest[~reduced.carried, 1])), 1e-12)
    legs, arms, middle = [], [], []
    for r in leaves:
        if reduced.mirror[r] < 0 or reduced.mirror[r] == r:
            middle.append(r)
        elif not reduced.optional[r]:
            (legs if rest[r, 1] - reduced.floor < FEET * span else arms).append(r)
    head = max(middle, key=lambda r: rest[r, 1]) if middle else None
    return {"legs": legs, "arms": arms, "head": head}


def check_embedding(field_, reduced, positions, names, placed, upright=True, to_field=None):
    """Check an embedded template as a rigger would (see the module notes).

    Parameters
    ----------
    field_ : DistanceField
        The mesh's, in the frame ``to_field`` takes rigedit's to (the same one by default).
    reduced : ReducedTemplate
        The template as the embedding reduced it.
    positions : (J, 3) float64
        Every template joint, template order, in rigedit's frame (+Y up, facing +Z).
    names : list[str]
        The template's joint names.
    placed : iterable of str
        Joints placed from the mesh (the others were carried from the template).
    upright : bool
        The template stands tall (a biped).
    to_field : (4, 4) float64, optional
        Rigedit's frame -> the field's (a rotation and a translation): one field serves
        every orientation tried.

    Returns
    -------
    Confidence
    """
    positions = np.asarray(positions, dtype=np.float64)
    m = np.eye(4) if to_field is None else np.asarray(to_field, dtype=np.float64)
    in_field = positions @ m[:3, :3].T + m[:3, 3]
    placed_idx = {names.index(n) for n in placed}
    # the inside cells' centres, back in rigedit's frame: its floor and height
    cells = field_.points(np.argwhere(field_.inside))
    ys = (cells - m[:3, 3]) @ m[:3, :3][:, 1]
    floor, height = float(ys.min() - 0.5 * field_.h), float(np.ptp(ys) + field_.h)
    out = Confidence()
    roles = limb_roles(reduced)
    limb_check(out, field_, reduced, in_field, names, roles, height)
    if upright:
        upright_check(out, reduced, positions, names, roles, floor, height)
    mirror_check(out, reduced, positions, names, placed_idx, height)
    inside_check(out, field_, reduced, in_field, names, placed_idx)
    length_check(out, reduced, positions, names, placed_idx)
    return out


def fit_score(reduced, positions):
    """A scale-free measure of how well embedded joints fit the template (lower is better).

    The embedding's own cost compares bone lengths with the template's times the scale it
    took from the mesh's height, and the height depends on the orientation tried; so
    orientations are compared on this instead: over the reduced bones, the bone direction
    term of the embedding (3 (1 - cos) of the angle to the template's, in rigedit's frame)
    plus twice the squared log of each chain's length ratio against the median ratio.

    Parameters
    ----------
    reduced : ReducedTemplate
    positions : (J, 3) float64
        Every template joint, embedded, in rigedit's frame.

    Returns
    -------
    float
        The mean per reduced bone.
    """
    positions = np.asarray(positions, dtype=np.float64)
    terms, ratios = [], []
    for r in range(1, len(reduced.joints)):
        a, b = reduced.joints[reduced.parent[r]], reduced.joints[r]
        t = reduced.rest[b] - reduced.rest[a]
        e = positions[b] - positions[a]
        lt, le = np.linalg.norm(t), np.linalg.norm(e)
        if lt <= 1e-12:
            continue
        cos = float(t @ e) / (lt * le) if le > 1e-12 else -1.0
        terms.append(3.0 * (1.0 - cos))
        ratios.append(max(le, 1e-12) / lt)
    if not terms:
        return 0.0
    logs = np.log(ratios)
    return float(np.mean(np.asarray(terms) + 2.0 * (logs - np.median(logs)) ** 2))
