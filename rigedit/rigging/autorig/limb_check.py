"""The limb check of an embedding (:mod:`.confidence`): each paired limb lies in a part of
the mesh that ends, and narrows on its way there.

Cut the mesh's inside (its distance field's cells) across each limb chain :data:`CUT_AT` of
the way along it (its section must close within :data:`SECTION` of the height): the part
holding the limb's end must be cut off from the body (the root joint's part), hold no other
limb's end, and be under :data:`LIMB_VOLUME` of the volume. A thigh laid along the torso or
an arm in the head fails; an ear passes (it ends), which the upright check catches. And a
limb narrows from where it leaves the body to its end: one that thickens by more than
:data:`BULGE` on the way passes through a head or a body (legs from the hips through the
neck and the head into the ears of an upside-down cartoon).

Pure numpy/scipy.
"""
from __future__ import annotations

import numpy as np
from scipy import ndimage

__all__ = ["limb_check", "Names", "LIMB_VOLUME", "CUT_AT", "SECTION", "BULGE"]

#: Largest share of the mesh's inside volume one limb's cut-off part may hold (a human leg
#: below the knee is about 5%, a whole leg about 17%).
LIMB_VOLUME = 0.12
#: Where along a limb chain (fraction of its length from the joint it leaves) the cut is.
CUT_AT = 0.8
#: Largest distance from a limb's bone to the rim of its cross-section, as a fraction of the
#: height: a limb is thinner (a human thigh's radius is about 5% of the height).
SECTION = 0.15
#: Largest factor a limb may thicken by along its chain (see :func:`_bulge`). The depth is
#: sampled on the bones, which need not run down a limb's middle: right rigs of Xbot,
#: RiggedFigure and CesiumMan reach 1.9-2.8 (a knee bone near the skin); an upside-down
#: cartoon's legs through its head 5.2.
BULGE = 3.5


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


def limb_check(out, field_, reduced, positions, names, roles, height):
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
        label = reduced.label(Names(names), r)
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


class Names:
    """The bit of a skeleton :meth:`ReducedTemplate.label` reads."""

    def __init__(self, names):
        self.names = names
