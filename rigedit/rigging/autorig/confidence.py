"""Would a rigger sign this embedding off? The checks run after it (issue 17, section 1).

An embedding's cost says how well the template's bones fit the medial graph; it does not
say that the arms are in the arms. Ears as long as short arms, a head as big as the chest:
the cheapest fit may put the arms in the ears or the hips at the chin, at a lower cost than
a right rig of another mesh. So, as a rigger would, :func:`check_embedding` looks at the
result itself, in rigedit's frame (+Y up, facing +Z, the mirror plane x = const):

* **limb** -- each paired limb chain of the template (arms, legs) lies in a part of the
  mesh that ends: cut the mesh's inside (its distance field's cells) across each limb
  :data:`CUT_AT` of the way along its chain (its section must close within :data:`SECTION`
  of the height), and the part holding the limb's end must be cut off from
  the body (the root joint's part), hold no other limb's end, and be under
  :data:`LIMB_VOLUME` of the volume. A thigh laid along the torso or an arm in the head
  fails; an ear passes (it ends), which the next check catches. And a limb narrows from
  where it leaves the body to its end: one that thickens by more than :data:`BULGE` on
  the way passes through a head or a body (legs from the hips through the neck and the
  head into the ears of an upside-down cartoon);
* **upright** (an upright template only) -- the hips in the lower part of the height (at
  most :data:`HIPS_HIGH` of it) and the head joint above both ends of each arm's first
  bone (the shoulders);
* **mirror** -- each left joint is the mirror image of its right partner, and each joint
  of the middle plane (spine, neck, head) on it, within :data:`MIRROR_TOLERANCE` of the
  height (a head in one ear is off the plane);
* **inside** -- no placed bone has more than :data:`OUTSIDE_SHARE` of its length more than
  :data:`OUT_CELLS` cells (of 128 along the longest side) outside the mesh;
* **lengths** -- each embedded chain's length against the template's, relative to the
  median of those ratios (so scale-free), within a factor :data:`STRETCH`.

Each failed check gives one line (the reason) and the joints in doubt; the margin to the
best alternative embedding (another orientation) is the caller's to add
(:mod:`.autorig`). Pure numpy/scipy.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from ...embedding.fit import FEET

__all__ = ["Confidence", "check_embedding", "fit_score", "limb_roles", "LIMB_VOLUME",
           "HIPS_HIGH", "MIRROR_TOLERANCE", "OUTSIDE_SHARE", "STRETCH"]

#: Largest share of the mesh's inside volume one limb's cut-off part may hold (a human leg
#: below the knee is about 5%, a whole leg about 17%).
LIMB_VOLUME = 0.12
#: Where along a limb chain (fraction of its length from the joint it leaves) the cut is.
CUT_AT = 0.8
#: Largest distance from a limb's bone to the rim of its cross-section, as a fraction of the
#: height: a limb is thinner (a human thigh's radius is about 5% of the height).
SECTION = 0.15
#: Highest hips (reduced root) of an upright template, as a fraction of the height above
#: the floor: a standing human's are at 50-55%, a big-headed cartoon's lower.
HIPS_HIGH = 0.65
#: Largest distance between a joint and its partner's mirror image, fraction of the height.
MIRROR_TOLERANCE = 0.06
#: Largest factor a limb may thicken by along its chain (see :func:`_bulge`). The depth is
#: sampled on the bones, which need not run down a limb's middle: right rigs of Xbot,
#: RiggedFigure and CesiumMan reach 1.9-2.8 (a knee bone near the skin); an upside-down
#: cartoon's legs through its head 5.2.
BULGE = 3.5
#: Largest share of a placed bone's length that may lie more than :data:`OUT_CELLS` cells
#: of the distance field outside the mesh (a chord across a bent thin arm may leave it by a
#: cell: homer's upper arms by 1.3, 1.6% of his height).
OUTSIDE_SHARE = 0.25
OUT_CELLS = 2
#: Largest factor between a chain's length ratio (embedded / template) and the median one.
STRETCH = 2.5


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


def _chain_points(reduced, positions, r):
    return positions[reduced.chains[r]]


def _along(points, fraction):
    """The point ``fraction`` of the way along a polyline (K, 3)."""
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    total = seg.sum()
    if total <= 0:
        return points[-1]
    target = fraction * total
    k = int(np.searchsorted(np.cumsum(seg), target))
    k = min(k, len(seg) - 1)
    before = np.cumsum(seg)[k] - seg[k]
    t = (target - before) / max(seg[k], 1e-300)
    return points[k] + t * (points[k + 1] - points[k])


def _cell(field_, point):
    idx = np.round((np.asarray(point) - field_.origin) / field_.h).astype(int)
    return tuple(np.clip(idx, 0, np.array(field_.inside.shape) - 1))


def _first_kept(field_, kept, points, reach=2):
    """The kept cell (inside, not cut) nearest the first of ``points`` that has one within
    ``reach`` cells, as a cell index (a joint at a thin limb's tip may sit just outside)."""
    for p in points:
        c = np.array(_cell(field_, p))
        lo = np.maximum(c - reach, 0)
        box = kept[tuple(slice(a, b + reach + 1) for a, b in zip(lo, c))]
        hits = np.argwhere(box)
        if len(hits):
            k = np.argmin(np.linalg.norm(hits + lo - c, axis=1))
            return tuple(hits[k] + lo)
    return None


def _cut_section(kept, field_, points, reach):
    """Clear, in ``kept``, the limb's cross-section two cells thick across the polyline
    ``points`` (K, 3) at :data:`CUT_AT` of its length: the inside cells of that slab joined
    to the chain there, within ``reach`` of it. Returns whether the section closes within
    ``reach`` (False: the chain runs through something wider than a limb)."""
    centre = _along(points, CUT_AT)
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    k = min(int(np.searchsorted(np.cumsum(seg), CUT_AT * seg.sum())), len(seg) - 1)
    axis = (points[k + 1] - points[k]) / max(seg[k], 1e-300)
    h = field_.h
    radius = reach / h + 1.0
    c = (centre - field_.origin) / h
    lo = np.maximum(np.floor(c - radius).astype(int), 0)
    hi = np.minimum(np.ceil(c + radius).astype(int) + 1, kept.shape)
    if np.any(hi <= lo):
        return False
    sl = tuple(slice(a, b) for a, b in zip(lo, hi))
    rel = [g - ci for g, ci in zip(np.ogrid[sl], c)]
    along = sum(r * a for r, a in zip(rel, axis))
    across = sum(r * r for r in rel) - along * along
    slab = field_.inside[sl] & (np.abs(along) <= 1.0) & (across <= radius * radius)
    labels, _ = ndimage.label(slab, structure=np.ones((3, 3, 3)))
    near = np.argwhere(labels > 0)
    if not len(near):
        return False
    d = np.linalg.norm(near + lo - c, axis=1)
    section = labels == labels[tuple(near[np.argmin(d)])]
    kept[sl] &= ~section
    return bool(np.sqrt(across[section].max()) < radius - 1.5)


def _limb_check(out, field_, reduced, positions, names, roles, height):
    limbs = roles["legs"] + roles["arms"]
    if not limbs:
        return
    inside = field_.inside
    kept = inside.copy()
    reach = SECTION * height
    closed = {r: _cut_section(kept, field_, _chain_points(reduced, positions, r), reach)
              for r in limbs}
    labels, _ = ndimage.label(kept)
    volume = max(int(inside.sum()), 1)
    trunk = [reduced.joints[k] for k in range(len(reduced.joints)) if reduced.mirror[k] < 0]
    root_cell = _first_kept(field_, kept, positions[trunk])
    body = labels[root_cell] if root_cell is not None else -1
    ends = {}
    for r in limbs:
        # the end, and back towards the cut (but not to it: before it is the body)
        tips = [_along(_chain_points(reduced, positions, r), f)
                for f in np.linspace(1.0, CUT_AT + 0.05, 4)]
        c = _first_kept(field_, kept, tips)
        ends[r] = labels[c] if c is not None else 0
    sizes = np.bincount(labels.ravel())
    worst = bulge_worst = 0.0
    for r in limbs:
        part = ends[r]
        label = reduced.label(_Names(names), r)
        joints = [names[j] for j in reduced.chains[r][1:]]
        if part == 0:
            out.fail("limb", f"the {label} has no mesh around its end", joints)
            continue
        sharing = [q for q in limbs if q != r and ends[q] == part]
        share = float(sizes[part]) / volume
        worst = max(worst, share if part != body else 1.0)
        bulge = _bulge(field_, _chain_points(reduced, positions, r))
        bulge_worst = max(bulge_worst, bulge)
        if bulge > BULGE:
            out.fail("limb", f"the {label} passes through a part {bulge:.1f} times as thick "
                             "as where it came from (through a head or a body?)", joints)
        elif not closed[r]:
            out.fail("limb", f"the {label} does not lie in a limb of the mesh: its section "
                             f"{100 * CUT_AT:.0f}% along it is wider than "
                             f"{200 * SECTION:.0f}% of the height (in the torso?)", joints)
        elif part == body:
            out.fail("limb", f"the {label} does not lie in a limb of the mesh: cut "
                             f"{100 * CUT_AT:.0f}% along, its end stays joined to the body "
                             "(along the torso?)", joints)
        elif sharing:
            out.fail("limb", f"the {label} shares a part of the mesh with another limb",
                     joints)
        elif share > LIMB_VOLUME:
            out.fail("limb", f"the {label} lies in a part holding {100 * share:.0f}% of the "
                             f"volume, over the {100 * LIMB_VOLUME:.0f}% of a limb", joints)
    out.measures["limb volume"] = worst
    out.measures["bulge"] = bulge_worst


def _bulge(field_, points):
    """How many times a limb thickens along its chain (its depth, sampled from 10% to 90%
    of the way, against the thinnest depth before): about 1 for a limb, which narrows from
    its root to its end."""
    depth = np.maximum(field_(np.array([_along(points, f) for f in np.linspace(.1, .9, 41)])),
                       1.5 * field_.h)
    return float(np.max(depth[1:] / np.minimum.accumulate(depth)[:-1]))


class _Names:
    """The bit of a skeleton :meth:`ReducedTemplate.label` reads."""

    def __init__(self, names):
        self.names = names


def _upright_check(out, reduced, positions, names, roles, floor, height):
    hips = reduced.joints[0]
    rise = (positions[hips, 1] - floor) / max(height, 1e-12)
    out.measures["hips height"] = float(rise)
    if rise > HIPS_HIGH:
        out.fail("upright", f"the hips ({names[hips]}) are at {100 * rise:.0f}% of the height, "
                            f"expected at most {100 * HIPS_HIGH:.0f}% for an upright template",
                 [names[hips]])
    head = roles["head"]
    if head is None or not roles["arms"]:
        return
    hj = reduced.joints[head]
    shoulders = [j for r in roles["arms"] for j in reduced.chains[r][1:3]]
    gap = positions[hj, 1] - positions[shoulders, 1].max()
    out.measures["head over shoulders"] = float(gap / max(height, 1e-12))
    if gap <= 0:
        low = [names[j] for j in shoulders if positions[j, 1] >= positions[hj, 1]]
        out.fail("upright", f"the head ({names[hj]}) is not above the shoulders "
                            f"({', '.join(low)}): arms in the ears or the head?",
                 [names[hj]] + low)


def _mirror_check(out, reduced, positions, names, placed, height):
    m = reduced.mirror_all
    middle = [j for j in np.flatnonzero(m == -2) if j in placed]
    plane = float(np.median(positions[middle, 0])) if middle else 0.0
    worst, bad = 0.0, []
    for j in sorted(placed):
        k = m[j]
        if k <= j or k not in placed:
            continue
        image = positions[k] * [-1, 1, 1] + [2 * plane, 0, 0]
        off = float(np.linalg.norm(positions[j] - image)) / max(height, 1e-12)
        worst = max(worst, off)
        if off > MIRROR_TOLERANCE:
            bad.append((off, names[j], names[k]))
    # a joint of the middle plane (spine, neck, head; placed, or carried along from its
    # chain) stays on it
    root_x = reduced.rest[reduced.joints[0], 0]
    on_plane = np.abs(reduced.rest[:, 0] - root_x) < 1e-3 * reduced.size
    for j in np.flatnonzero((m == -2) & ~reduced.carried & on_plane):
        off = abs(positions[j, 0] - plane) / max(height, 1e-12)
        worst = max(worst, off)
        if off > MIRROR_TOLERANCE:
            bad.append((off, names[j], None))
    out.measures["mirror"] = float(worst)
    if bad:
        bad.sort(reverse=True)
        off, a, b = bad[0]
        what = (f"{a} and {b} are not mirror images" if b else
                f"{a} is off the middle plane")
        out.fail("mirror", f"{what}: {100 * off:.0f}% of the height off, over "
                           f"{100 * MIRROR_TOLERANCE:.0f}%"
                           + (f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""),
                 [n for _, x, y in bad for n in (x, y) if n])


def _inside_check(out, field_, reduced, positions, names, placed):
    worst, bad = 0.0, []
    t = np.linspace(0.0, 1.0, 11)
    # the field holds -h anywhere far outside, so "how far out" is read from the inside
    # mask grown by OUT_CELLS cells instead
    near = ndimage.binary_dilation(field_.inside, iterations=OUT_CELLS)
    for j in sorted(placed):
        p = reduced.parents[j]
        if p < 0 or p not in placed or reduced.carried[p]:   # a ground-level root: outside
            continue
        seg = positions[p] + t[:, None] * (positions[j] - positions[p])
        cells = np.round((seg - field_.origin) / field_.h).astype(int)
        ok = np.all((cells >= 0) & (cells < near.shape), axis=1)
        out_of = ~ok
        out_of[ok] = ~near[tuple(cells[ok].T)]
        share = float(np.mean(out_of))
        worst = max(worst, share)
        if share > OUTSIDE_SHARE:
            bad.append((share, names[p], names[j]))
    out.measures["outside"] = worst
    if bad:
        bad.sort(reverse=True)
        share, a, b = bad[0]
        out.fail("inside", f"the bone {a} -> {b} leaves the mesh ({100 * share:.0f}% of it "
                           "outside)" + (f"; {len(bad) - 1} more bones too" if len(bad) > 1
                                         else ""),
                 [n for _, x, y in bad for n in (x, y)])


def _length_check(out, reduced, positions, names, placed):
    ratios = {}
    for r in range(1, len(reduced.joints)):
        chain = reduced.chains[r]
        if reduced.chain_length[r] <= 0 or not all(j in placed or j == chain[0]
                                                   for j in chain[1:]):
            continue
        emb = float(np.linalg.norm(np.diff(positions[chain], axis=0), axis=1).sum())
        ratios[r] = emb / reduced.chain_length[r]
    if len(ratios) < 2:
        return
    med = float(np.median(list(ratios.values())))
    if med <= 0:
        return
    factors = {r: max(v / med, med / max(v, 1e-300)) for r, v in ratios.items()}
    worst = max(factors, key=factors.get)
    out.measures["stretch"] = float(factors[worst])
    if factors[worst] > STRETCH:
        how = "long" if ratios[worst] > med else "short"
        out.fail("lengths", f"the {reduced.label(_Names(names), worst)} is "
                            f"{factors[worst]:.1f} times too {how} for the template's "
                            f"proportions (at most {STRETCH:g})",
                 [names[j] for j in reduced.chains[worst][1:]])


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
    _limb_check(out, field_, reduced, in_field, names, roles, height)
    if upright:
        _upright_check(out, reduced, positions, names, roles, floor, height)
    _mirror_check(out, reduced, positions, names, placed_idx, height)
    _inside_check(out, field_, reduced, in_field, names, placed_idx)
    _length_check(out, reduced, positions, names, placed_idx)
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
