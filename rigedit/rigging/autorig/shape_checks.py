"""The checks of an embedding's shape (:mod:`.confidence`): upright, mirror, inside, lengths.

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

Each check adds its worst measure to ``out.measures`` and, failed, a reason and the joints
in doubt (``out.fail``, :class:`.confidence.Confidence`). Pure numpy/scipy.
"""
from __future__ import annotations

import numpy as np
from scipy import ndimage

from .limb_check import Names

__all__ = ["upright_check", "mirror_check", "inside_check", "length_check", "HIPS_HIGH",
           "MIRROR_TOLERANCE", "OUTSIDE_SHARE", "OUT_CELLS", "STRETCH"]

#: Highest hips (reduced root) of an upright template, as a fraction of the height above
#: the floor: a standing human's are at 50-55%, a big-headed cartoon's lower.
HIPS_HIGH = 0.65
#: Largest distance between a joint and its partner's mirror image, fraction of the height.
MIRROR_TOLERANCE = 0.06
#: Largest share of a placed bone's length that may lie more than :data:`OUT_CELLS` cells
#: of the distance field outside the mesh (a chord across a bent thin arm may leave it by a
#: cell: homer's upper arms by 1.3, 1.6% of his height).
OUTSIDE_SHARE = 0.25
OUT_CELLS = 2
#: Largest factor between a chain's length ratio (embedded / template) and the median one.
STRETCH = 2.5


def upright_check(out, reduced, positions, names, roles, floor, height):
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


def mirror_check(out, reduced, positions, names, placed, height):
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


def inside_check(out, field_, reduced, positions, names, placed):
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


def length_check(out, reduced, positions, names, placed):
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
        out.fail("lengths", f"the {reduced.label(Names(names), worst)} is "
                            f"{factors[worst]:.1f} times too {how} for the template's "
                            f"proportions (at most {STRETCH:g})",
                 [names[j] for j in reduced.chains[worst][1:]])
