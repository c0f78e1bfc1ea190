"""The continuous refinement: every embedded joint solved at once, template shape against mesh.

The discrete search puts the reduced joints on sphere centres (sparse where the body is
thick) and the inner joints of each chain follow the template chain mapped onto it. Then
all the joints of the embedded chains are solved together, as-rigid-as-possible fashion,
in a few rounds of one small linear least-squares problem each (joints x joints, and the
scale), with these terms:

* shape: every template bone, scaled, should be the bone in the mesh. A bone turns from
  the template's direction towards its present one by how slender its part is (a limb: the
  mesh shows which way it points; a spine in a trunk: it does not, and the frames are
  shared, so the template's direction stands). A chain whose embedded ends are much closer
  or further apart than the template's (short cartoon arms) takes that proportion.
* data: every joint to the middle of the mesh's cross-section across its bone
  (:func:`rigedit.embedding.centre.centre_joints`), weighted by how thin the part is: the
  middle of a limb is where its joints are, the middle of a trunk says little (a quadruped's
  spine runs along its back, not through its belly).
* feet on the ground at the template's height above its ground; left and right joints
  mirror images across the mesh's middle plane, middle joints on it; the scale held to the
  one the heights and areas gave; a joint that left the mesh pulled back to the medial
  spheres, and finally stepped back inside.

The weights are set by reasoning (see each constant), not learned.
"""
from __future__ import annotations

import numpy as np

from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from .place import least_rotation
from .centre import centre_joints

__all__ = ["fit_joints"]

#: Weight of a joint's data term at a thin part, against 1 per template bone: the middle of
#: a limb is trusted four times as much as the template's bend there (a crouch, an elbow).
W_DATA = 2.0
#: Thickness (depth, as a fraction of the scaled template size) at which the data weight
#: has halved: 2% is a wrist or an ankle on a human, 10% a trunk.
THIN = 0.005
ROUNDS = 6
#: A bone follows the direction the mesh gives it by how slender its part is: fully when
#: the part's radius is small against the bone's length (an arm, a leg: the mesh shows
#: which way they point), hardly when it is not (the spine in a trunk, a clavicle in a
#: chest: the mesh says nothing of their direction, the template does). Half-way when the
#: radius is a third of the length.
SLENDER = 3.0
#: Feet on the ground: joints whose template height above the template's ground is under
#: this fraction of the joints' height span (ankles, hooves) keep that height above the
#: mesh's lowest point, times the scale. Limbs say where a joint is across them, not along
#: them; standing on the ground is what fixes a character's joints vertically.
FEET = 0.12
W_FEET = 1.0
#: Chains keep the template's proportions unless the embedded chord differs by more than
#: this (log ratio, ~16%); beyond it they take the excess (see ``_proportions``).
PROPORTION_FREE = 0.15
#: A tail's chain may take from a quarter to four times the template's length (a pug's
#: stub, a horse's tail): other chains stay within 0.6-1.6 of theirs.
TAIL_RANGE = (0.25, 4.0)
#: Weight pulling a joint that left the mesh back to the nearest medial point.
W_INSIDE = 10.0
#: Left-right symmetry, per coordinate: half a bone's weight, so that an asymmetric pose
#: (one arm raised) still follows the mesh while a symmetric one comes out symmetric.
W_MIRROR_FIT = 0.5
#: Hold of the scale, against all bones together: a scale 1% off costs as much as every
#: bone 1% off (firm: it came from the template mesh's height), or a tenth of that (weak:
#: it came from the skeleton's height, good to 10-20%, so the bones may move it).
W_SCALE_FIRM = 1.0
W_SCALE_WEAK = 0.1
#: Weight of a pinned joint (a user's hint) at its point: far above every other term, so the
#: others arrange themselves around it.
W_PIN = 1000.0


def _chain_of(template, n):
    """For every template joint, the reduced joint whose chain it ends or lies inside."""
    owner = np.full(n, -1)
    for r in range(1, len(template.joints)):
        owner[template.chains[r][1:]] = r
    return owner


def fit_joints(field, template, positions, scale, floor, hold_scale=W_SCALE_WEAK,
               medial=None, plane=None, pins=None):
    """Solve the embedded chain joints for shape and middle together.

    Parameters
    ----------
    field : DistanceField
    template : ReducedTemplate
    positions : (J, 3) float64
        Every template joint as placed from the reduced joints (NaN where not yet placed).
    scale : float
    floor : float
        The mesh's ground height (its lowest point).
    plane : float, optional
        The mesh's middle plane x = plane: left and right joints mirror each other across
        it and middle joints lie on it (``W_MIRROR_FIT``); no symmetry rows without it.
    medial : (M, 3) float64, optional
        Points inside the mesh (the medial spheres' centres) to pull back joints that left it.
    hold_scale : float
        How firmly the scale stays (``W_SCALE_FIRM`` when it came from the template's mesh).
    pins : dict[int, (3,) float64], optional
        Template joint -> a point it must be at (the user's hints): held there with
        ``W_PIN`` and put exactly there at the end.

    Returns
    -------
    positions : (J, 3) float64
        The embedded chain joints solved; other rows unchanged.
    scale : float
        The scale solved with them.
    """
    rest, parents = template.rest, template.parents
    n = len(rest)
    owner = _chain_of(template, n)
    root = template.joints[0]
    live = np.all(np.isfinite(positions), axis=1) & ~template.carried
    live &= (owner >= 0) | (np.arange(n) == root)
    idx = np.flatnonzero(live)
    if len(idx) < 2:
        return positions, scale
    slot = np.full(n, -1)
    slot[idx] = np.arange(len(idx))
    bones = [(parents[j], j) for j in idx if parents[j] >= 0 and live[parents[j]]]
    x = positions[idx].copy()
    thin = THIN * template.size * scale
    k = len(idx)
    pb = np.array([slot[p] for p, _ in bones])
    cb = np.array([slot[j] for _, j in bones])
    tb = _template_bones(template, positions, scale, bones, owner)
    # rows of the form  x[i, dim] - coef * scale = value  (weight w)
    rows = _feet_rows(template, idx, floor) + _symmetry_rows(template, idx, slot, plane)
    scale0 = scale
    medial_tree = cKDTree(medial) if medial is not None and len(medial) else None
    medial = medial if medial_tree is not None else None
    pinned = np.array([slot[j] for j in (pins or {}) if slot[j] >= 0], dtype=np.int64)
    pin_at = np.array([pins[j] for j in (pins or {}) if slot[j] >= 0]).reshape(-1, 3)
    # the root's direction: to its first child's joint
    first = [slot[j] for p, j in bones if p == root]
    for _ in range(ROUNDS):
        v = _followed_bones(field, x, pb, cb, tb)
        direction = np.full((k, 3), np.nan)
        direction[cb] = x[cb] - x[pb]
        if first:
            direction[slot[root]] = x[first[0]] - x[slot[root]]
        target, lam = _data_targets(field, x, direction, thin, medial, medial_tree)
        target[pinned], lam[pinned] = pin_at, W_PIN
        try:
            x_new, s_new = _solve(k, pb, cb, v, lam, target, scale0, rows, hold_scale)
        except np.linalg.LinAlgError:
            break
        if not (np.all(np.isfinite(x_new)) and np.isfinite(s_new) and s_new > 0):
            break  # keep the last good round rather than spread a degenerate one
        x, scale = x_new, s_new
    if medial is not None:
        x = _step_inside(field, x, medial[medial_tree.query(x)[1]])
    x[pinned] = pin_at
    out = positions.copy()
    out[idx] = x
    return out, scale


def _template_bones(template, positions, scale, bones, owner):
    """(B, 3) each of ``bones`` (parent, joint) as the template has it, times its chain's
    proportion factor (:func:`_proportions`; a tail's first bone keeps its length)."""
    rest = template.rest
    tb = np.array([rest[j] - rest[p] for p, j in bones])
    factor = _proportions(template, positions, scale)[[owner[j] for _, j in bones]]
    if template.tail is not None:   # a tail's first bone (base to tail root) keeps its length
        roots = {template.chains[r][1] for r in np.flatnonzero(template.tail)}
        factor[[i for i, (_, j) in enumerate(bones) if j in roots]] = 1.0
    return tb * factor[:, None]


def _feet_rows(template, idx, floor):
    """Rows (see :func:`_solve`) holding each foot joint among ``idx`` (template height
    above the template's ground under :data:`FEET` of the joints' span) at that height
    times the scale above the mesh's ``floor``."""
    rest = template.rest
    span = np.ptp(rest[idx, 1])
    low = rest[idx, 1] - template.floor
    return [([(i, 1, 1.0)], low[i], floor, W_FEET) for i in np.flatnonzero(low < FEET * span)]


def _followed_bones(field, x, pb, cb, tb):
    """(B, 3) the template bones ``tb`` turned towards their present directions (``x[cb] -
    x[pb]``) by how thin their part is: limbs follow the mesh, the trunk keeps the
    template's directions (frames are shared)."""
    cur = x[cb] - x[pb]
    mid_depth = np.maximum(field(0.5 * (x[cb] + x[pb])), 0.0)
    follow = 1.0 / (1.0 + (SLENDER * mid_depth / np.maximum(
        np.linalg.norm(cur, axis=1), 1e-12)) ** 2)
    return np.array([Rotation.from_rotvec(follow[i] * least_rotation(tb[i], cur[i]).as_rotvec())
                     .apply(tb[i]) for i in range(len(tb))])


def _data_targets(field, x, direction, thin, medial, medial_tree):
    """``(target, lam)``: where each joint ``x`` (K, 3) should be, the middle of the mesh's
    cross-section across its bone ``direction`` (K, 3), and how much that counts (more
    where the part is thin); a joint that left the mesh goes back to the nearest medial
    point ``medial`` (M, 3), firmly."""
    target = centre_joints(field, x, direction)
    depth = np.maximum(field(target), 0.0)
    lam = W_DATA / (1.0 + (depth / thin) ** 2)
    if medial is not None:
        # a joint pushed out of the mesh (a limb shorter than the template's) goes back
        # to the nearest medial sphere centre, firmly
        out_ = field(x) < 0.5 * field.h
        if out_.any():
            target[out_] = medial[medial_tree.query(x[out_])[1]]
            lam[out_] = W_INSIDE
    return target, lam


def _proportions(template, positions, scale):
    """(R,) length factor of each reduced chain: its embedded chord over the scaled template
    chord, outside a dead zone of +-``PROPORTION_FREE`` (log) and clipped to [0.6, 1.6]
    (a tail: from its root joint, within ``TAIL_RANGE``).

    The discrete embedding puts chain ends where the mesh has them (hands at the ends of
    arms); a character whose arms or legs are much shorter or longer than the template's
    keeps that here, while the small differences (a chain end a few centimetres off on a
    sparse graph) leave the template's proportions alone."""
    rest = template.rest
    out = np.ones(len(template.joints))
    for r in range(1, len(template.joints)):
        tail = template.tail is not None and template.tail[r] and len(template.chains[r]) > 2
        a, b = template.chains[r][1 if tail else 0], template.chains[r][-1]
        if np.all(np.isfinite(positions[[a, b]])):
            ratio = np.linalg.norm(positions[b] - positions[a]) / max(
                scale * np.linalg.norm(rest[b] - rest[a]), 1e-12)
            excess = np.log(max(ratio, 1e-12))
            excess = np.sign(excess) * max(abs(excess) - PROPORTION_FREE, 0.0)
            lo, hi = TAIL_RANGE if tail else (0.6, 1.6)
            out[r] = np.clip(np.exp(excess), lo, hi)
    return out


def _step_inside(field, points, towards, steps=16):
    """Points outside the mesh moved along the segment towards ``towards`` (inside points,
    one per point) to the first place a quarter cell deep; points inside stay."""
    points = np.array(points, dtype=np.float64)
    out_ = np.flatnonzero(field(points) <= 0.0)
    if len(out_):
        t = np.linspace(0.0, 1.0, steps + 1)
        a, b = points[out_], towards[out_]
        path = a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]
        deep = field(path.reshape(-1, 3)).reshape(len(out_), -1) > 0.25 * field.h
        first = np.where(deep.any(axis=1), deep.argmax(axis=1), steps)
        points[out_] = path[np.arange(len(out_)), first]
    return points


def _symmetry_rows(template, idx, slot, plane):
    """Rows tying mirror joints (x_a + x_b = 2 plane, equal y and z) and middle joints
    (x = plane)."""
    if plane is None:
        return []
    rows = []
    live = set(idx.tolist())
    for j in idx:
        m = template.mirror_all[j]
        if m > j and m in live:
            a, b = slot[j], slot[m]
            rows.append(([(a, 0, 1.0), (b, 0, 1.0)], 0.0, 2.0 * plane, W_MIRROR_FIT))
            rows += [([(a, d, 1.0), (b, d, -1.0)], 0.0, 0.0, W_MIRROR_FIT) for d in (1, 2)]
        elif m == -2:
            rows.append(([(slot[j], 0, 1.0)], 0.0, plane, W_MIRROR_FIT))
    return rows


def _solve(k, pb, cb, v, lam, target, scale, extra, hold_scale):
    """Least squares in joints (k, 3) and scale: bones = scale * v, joints = targets, and
    ``extra`` rows (entries, coef, value, weight): sum of c * x[slot, dim] over the
    entries (slot, dim, c), minus coef * scale, = value."""
    nb = len(pb)
    a = np.zeros((3 * nb + 3 * k + 1 + len(extra), 3 * k + 1))
    rhs = np.zeros(len(a))
    for d in range(3):
        rows = 3 * np.arange(nb) + d
        a[rows, 3 * cb + d] = 1.0
        a[rows, 3 * pb + d] = -1.0
        a[rows, -1] = -v[:, d]
        rows = 3 * nb + 3 * np.arange(k) + d
        w = np.sqrt(lam)
        a[rows, 3 * np.arange(k) + d] = w
        rhs[rows] = w * target[:, d]
    # hold on the scale, weighed against all the bones at once
    hold = hold_scale * float(np.linalg.norm(v))
    a[3 * nb + 3 * k, -1] = hold
    rhs[3 * nb + 3 * k] = hold * scale
    for row, (entries, coef, value, w) in enumerate(extra, start=3 * nb + 3 * k + 1):
        for i, dim, c in entries:
            a[row, 3 * i + dim] = w * c
        a[row, -1] = -w * coef
        rhs[row] = w * value
    sol = np.linalg.lstsq(a, rhs, rcond=None)[0]
    return sol[:-1].reshape(k, 3), float(sol[-1])
