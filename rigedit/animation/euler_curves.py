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
    out = np.empty_like(seq)
    out[:, axes] = _pick(seq, alt, np.asarray(references, dtype=float)[:, axes])
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
    fast = np.unwrap(base, period=360.0, axis=0)
    if len(fast) < 2 or np.max(np.abs(np.diff(fast, axis=0))) < 90.0:
        res = np.empty_like(fast)
        res[:, axes] = fast
        return res
    return _unwrap_sequential(seq, alt, axes, reference)


def _unwrap_sequential(seq, alt, axes, reference):
    """:func:`unwrap` key by key: each row the triple nearest the row before."""
    prev = None if reference is None else [float(x) for x in np.asarray(reference)[axes]]
    rows = []
    # sequential (each key depends on the one before), so on Python floats: numpy's per-call
    # overhead would make it ~30 times slower per key
    for a, b in zip(seq.tolist(), alt.tolist()):
        if prev is not None:
            a = [x + 360.0 * round((p - x) / 360.0) for x, p in zip(a, prev)]
            b = [x + 360.0 * round((p - x) / 360.0) for x, p in zip(b, prev)]
            if sum((x - p) ** 2 for x, p in zip(b, prev)) < \
                    sum((x - p) ** 2 for x, p in zip(a, prev)):
                a = b
        rows.append(a)
        prev = a
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
