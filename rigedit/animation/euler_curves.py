"""Rotations as Euler angles in degrees, per key, kept continuous for curves.

Convention: an Euler order such as ``"XYZ"`` names the axes in the order the rotations
apply, about the parent's fixed axes: ``R = Rz(z) Ry(y) Rx(x)`` for ``XYZ`` (Blender's
meaning of its Euler modes; scipy's *extrinsic* sequence ``"xyz"``). The angles are always
stored X, Y, Z whatever the order, so a curve's axis index is its axis.

Unwrapping: scipy returns each key's angles in principal ranges, which jump by 360 degrees
across +-180 and may pick the other of the two Euler triples of one rotation. Each key takes
the equivalent triple nearest the key before it (Blender's ``compatible_eul``): the two
triples ``(a, b, c)`` and ``(a + 180, 180 - b, c + 180)`` (angles in the order's sequence,
the same rotation for every Tait-Bryan order), each shifted by whole turns per angle.
"""
from __future__ import annotations

import warnings

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = ["EULER_ORDERS", "DEFAULT_ORDER", "quat_to_euler", "euler_to_quat", "unwrap", "principal",
           "nearest"]

EULER_ORDERS = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")
DEFAULT_ORDER = "XYZ"


def _check(order):
    if order not in EULER_ORDERS:
        raise ValueError(f"expected an Euler order in {EULER_ORDERS}, got {order!r}")
    return [("XYZ".index(a)) for a in order]


def _quat_mul(a, b):
    """(N, 4) Hamilton products ``a b`` of quaternions x, y, z, w."""
    ax, ay, az, aw = a.T
    bx, by, bz, bw = b.T
    return np.stack([aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz], axis=1)


def euler_to_quat(angles, order=DEFAULT_ORDER):
    """Quaternions (x, y, z, w) of Euler angles.

    Parameters
    ----------
    angles : (N, 3) or (3,) float
        Degrees about X, Y, Z.
    order : str

    Returns
    -------
    quats : (N, 4) or (4,) float
        The product of the three axis rotations, the first axis of ``order`` applied first
        (scipy's ``from_euler(order.lower(), ...)``; written out because scipy's per-call
        overhead is most of a pose's sampling time).
    """
    axes = _check(order)
    a = np.asarray(angles, dtype=np.float64)
    flat = a.reshape(-1, 3)
    half = np.radians(flat) / 2
    c, s = np.cos(half), np.sin(half)
    q = None
    for axis in axes:   # extrinsic: each later rotation multiplies from the left
        r = np.zeros((len(flat), 4))
        r[:, axis], r[:, 3] = s[:, axis], c[:, axis]
        q = r if q is None else _quat_mul(r, q)
    return q.reshape(a.shape[:-1] + (4,))


def _nearest_turn(angles, reference):
    return angles + 360.0 * np.round((reference - angles) / 360.0)


def _triples(angles, axes):
    """The two equivalent triples of each row, in the order's sequence: (2, N, 3)."""
    seq = np.asarray(angles, dtype=np.float64)[:, axes]
    alt = seq + np.array([180.0, 0.0, 180.0])
    alt[:, 1] = 180.0 - seq[:, 1]
    return seq, alt


def _pick(a, b, ref):
    """Per row, the triple of ``a`` or ``b`` (whole turns added) nearest ``ref``."""
    a, b = _nearest_turn(a, ref), _nearest_turn(b, ref)
    closer = np.sum((a - ref) ** 2, axis=-1) <= np.sum((b - ref) ** 2, axis=-1)
    return np.where(closer[..., None], a, b)


#: Degrees within which a middle angle of +-90 is gimbal lock (scipy gives 90 or 89.99...).
LOCK_TOLERANCE = 1e-6


def _lock_slide(seq, axes):
    """(N,) +1 or -1 for rows at gimbal lock (the middle angle at +-90 degrees: the first
    and last axes coincide, and ``(a + d, b, c + s d)`` is the same rotation for every d
    with this s), 0 elsewhere. ``seq``: (N, 3) angles in the order's sequence."""
    locked = np.abs(np.abs(seq[:, 1]) - 90.0) < LOCK_TOLERANCE
    out = np.zeros(len(seq))
    if locked.any():
        order = "".join("XYZ"[a] for a in axes)
        rows = seq[locked]
        xyz = np.empty_like(rows)
        xyz[:, axes] = rows
        moved = xyz.copy()
        moved[:, axes[0]] += 10.0
        moved[:, axes[2]] += 10.0
        dot = np.abs(np.sum(euler_to_quat(xyz, order) * euler_to_quat(moved, order), axis=1))
        out[locked] = np.where(dot > 1 - 1e-9, 1.0, -1.0)
    return out


def _slide(row, slide, ref):
    """A gimbal-locked ``row`` (3 floats, the order's sequence) slid along its family to the
    triple nearest ``ref`` (least squares on the first and last angle), whole turns added."""
    a, b, c = row
    # the family keeps c - s a (up to whole turns): take its turn nearest the reference's,
    # then the point of that line nearest the reference
    keep = c - slide * a
    keep += 360.0 * round(((ref[2] - slide * ref[0]) - keep) / 360.0)
    first = (ref[0] + slide * (ref[2] - keep)) / 2.0
    return [first, b + 360.0 * round((ref[1] - b) / 360.0), keep + slide * first]


def nearest(angles, order, references):
    """Each row of Euler angles as the equivalent triple nearest its own reference row.

    Parameters
    ----------
    angles, references : (N, 3) float
        Degrees X, Y, Z.
    order : str

    Returns
    -------
    angles : (N, 3) float
    """
    axes = _check(order)
    seq, alt = _triples(angles, axes)
    ref = np.asarray(references, dtype=float)[:, axes]
    picked = _pick(seq, alt, ref)
    slide = _lock_slide(seq, axes)
    for i in np.flatnonzero(slide):   # gimbal lock: a continuum of triples, not two
        picked[i] = _slide(seq[i].tolist(), slide[i], ref[i].tolist())
    out = np.empty_like(seq)
    out[:, axes] = picked
    return out


def unwrap(angles, order=DEFAULT_ORDER, reference=None):
    """Each row of Euler angles replaced by the equivalent triple nearest the row before.

    Parameters
    ----------
    angles : (N, 3) float
        Degrees X, Y, Z of N rotations in time order.
    order : str
    reference : (3,) float, optional
        What the first row is brought near (left in principal range when None).

    Returns
    -------
    angles : (N, 3) float
        The same rotations, continuous where the rotations are.
    """
    axes = _check(order)
    seq, alt = _triples(angles, axes)
    base = seq.copy()
    if reference is not None and len(seq):
        ref = np.asarray(reference, dtype=float)[axes]
        first = _pick(seq[0], alt[0], ref)
        if not np.array_equal(first, _nearest_turn(seq[0], ref)):
            base = alt.copy()      # the first key is on the other branch: stay on it
        base[0] = first
    # fast path: whole turns per axis on one branch (np.unwrap). When no step between rows
    # is 90 degrees or more, the other branch (180 away on two angles) is never nearer, so
    # this is what the key-by-key choice gives; else (through gimbal lock) key by key.
    slide = _lock_slide(seq, axes)
    fast = np.unwrap(base, period=360.0, axis=0)
    if not slide.any() and (len(fast) < 2 or np.max(np.abs(np.diff(fast, axis=0))) < 90.0):
        res = np.empty_like(fast)
        res[:, axes] = fast
        return res
    return _unwrap_sequential(seq, alt, axes, reference, slide)


def _unwrap_sequential(seq, alt, axes, reference, slide=None):
    """:func:`unwrap` key by key: each row the triple nearest the row before; a row at
    gimbal lock (``slide`` nonzero, see :func:`_lock_slide`) slid along its continuum of
    triples, to the row before, then to the middle of its two neighbours (the neighbours'
    own triples are unique: a key keyed (30, 90, 30) between (20, 75, 20) and (40, 75, 40)
    reads so, not (0, 90, 0), scipy's pick, a dip in two curves)."""
    prev = None if reference is None else [float(x) for x in np.asarray(reference)[axes]]
    rows = []
    slides = (_lock_slide(seq, axes) if slide is None else slide).tolist()
    # sequential (each key depends on the one before), so on Python floats: numpy's per-call
    # overhead would make it ~30 times slower per key
    for a, b, s in zip(seq.tolist(), alt.tolist(), slides):
        if prev is not None and s:
            a = _slide(a, s, prev)
        elif prev is not None:
            a = [x + 360.0 * round((p - x) / 360.0) for x, p in zip(a, prev)]
            b = [x + 360.0 * round((p - x) / 360.0) for x, p in zip(b, prev)]
            if sum((x - p) ** 2 for x, p in zip(b, prev)) < \
                    sum((x - p) ** 2 for x, p in zip(a, prev)):
                a = b
        rows.append(a)
        prev = a
    for i, s in enumerate(slides):
        if s and 0 < i < len(rows) - 1 and not slides[i + 1]:
            mid = [(p + n) / 2.0 for p, n in zip(rows[i - 1], rows[i + 1])]
            rows[i] = _slide(rows[i], s, mid)
        elif s and i == 0 and reference is None and len(rows) > 1 and not slides[1]:
            rows[0] = _slide(rows[0], s, rows[1])    # the first key: near the second
    out = np.array(rows, dtype=np.float64).reshape(-1, 3)
    res = np.empty_like(out)
    res[:, axes] = out
    return res


def principal(quats, order=DEFAULT_ORDER):
    """(N, 3) Euler angles (degrees X, Y, Z) of quaternions, each in scipy's principal
    range (not unwrapped)."""
    axes = _check(order)
    with warnings.catch_warnings():   # gimbal lock: scipy picks one of the triples, as we do
        warnings.simplefilter("ignore", UserWarning)
        seq = Rotation.from_quat(np.asarray(quats, dtype=np.float64).reshape(-1, 4)) \
            .as_euler(order.lower(), degrees=True)
    angles = np.empty_like(seq)
    angles[:, axes] = seq
    return angles


def quat_to_euler(quats, order=DEFAULT_ORDER, reference=None):
    """Continuous Euler angles (degrees X, Y, Z) of quaternions in time order.

    Parameters
    ----------
    quats : (N, 4) float
        x, y, z, w.
    order : str
    reference : (3,) float, optional
        Angles the first key is brought near (see :func:`unwrap`).

    Returns
    -------
    angles : (N, 3) float
    """
    return unwrap(principal(quats, order), order, reference)
