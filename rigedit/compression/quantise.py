"""Quantisation: values of a track normalised to its range in the bits the error allows.

Vectors (translation, scale): each component over the track's own range ``[lo, lo + ext]``
in ``b = ceil(log2(ext / step + 1))`` bits (the lecture's ``ceil(log2(range / precision))``),
``step`` the precision the tolerance allows; a component that does not move (``ext <= step``)
takes no bits at all.

Rotations, in smallest-three form (the largest-magnitude component dropped, the other three
stored, the dropped one rebuilt as ``sqrt(1 - x^2 - y^2 - z^2)``, made positive by the sign
of ``q``):

- ``fixed`` mode: when one component is at least :data:`FIXED_MIN` in magnitude in every key
  of the track, that one is dropped in every key: no per-key index, and the three others are
  range-quantised as vectors over the track's range (a joint's rotation in one clip spans
  little of [-1, 1], so this takes far fewer bits than 15 per component);
- ``per-key`` mode (a track that turns past where any one component stays large): each key
  stores its dropped component's index in 2 bits and the three others in ``[-1/sqrt 2,
  1/sqrt 2]`` in ``b`` bits each, b from the tolerance (15 gives ACL's 48-bit form; fewer
  where the error allows, more, up to 32, where a long chain needs it).

Dequantisation is the same arithmetic in the encoder and the decoder (float32 ranges,
float64 maths), so the key reducer measures exactly what will be decoded.
"""
from __future__ import annotations

import numpy as np

from .bits import MAX_FIELD_BITS

__all__ = ["FIXED_MIN", "PER_KEY", "SEGMENT", "SEGMENT_HEADER_BITS", "VectorCode",
           "SegmentCode", "segment_vectors", "segment_range", "quantise_vectors", "dequantise_vectors",
           "quantise_rotations", "rotation_from_three", "OTHERS"]

#: Smallest magnitude the dropped component may have in every key of a ``fixed`` track: the
#: rebuilt component's error is the others' times |xyz| / w, at most 3.2 here.
FIXED_MIN = 0.3
#: Rotation mode code of per-key smallest-three (0-3: the fixed dropped component).
PER_KEY = 4
#: The three stored components for each dropped one, in order.
OTHERS = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])
_HALF_SQRT2 = np.sqrt(0.5)


class VectorCode:
    """Quantised components of one track: ``lo`` and ``ext`` (3,) float32, ``bits`` (3,)
    int, ``codes`` (K, 3) uint64, ``step`` the precision asked for. ``values()`` gives what a
    decoder reads back."""

    __slots__ = ("lo", "ext", "bits", "codes", "step")

    def __init__(self, lo, ext, bits, codes, step=None):
        self.lo, self.ext, self.bits, self.codes, self.step = lo, ext, bits, codes, step

    def values(self):
        return dequantise_vectors(self.lo, self.ext, self.bits, self.codes)


def _float32_range(lo, hi):
    """float32 ``lo`` <= the true low and ``ext`` with ``lo + ext`` >= the true high."""
    lo32 = np.float32(lo)
    lo32 = np.where(lo32 > lo, np.nextafter(lo32, np.float32(-np.inf)), lo32).astype(np.float32)
    ext32 = np.float32(hi - lo32.astype(np.float64))
    low = lo32.astype(np.float64) + ext32.astype(np.float64) < hi
    ext32 = np.where(low, np.nextafter(ext32, np.float32(np.inf)), ext32).astype(np.float32)
    return lo32, np.maximum(ext32, np.float32(0))


def bits_for(extent, step):
    """Bits that hold ``extent`` at ``step`` (0 when ``extent <= step``), capped at 32."""
    extent = np.asarray(extent, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        need = np.ceil(np.log2(extent / step + 1.0))
    need = np.where(extent <= step, 0, need)
    return np.clip(need, 0, MAX_FIELD_BITS).astype(np.int64)


def dequantise_vectors(lo, ext, bits, codes):
    """Components back from codes: ``lo + code * ext / (2^bits - 1)``; a component of 0
    bits is the middle of its range. (K, 3) float64."""
    lo = np.asarray(lo, dtype=np.float64)
    ext = np.asarray(ext, dtype=np.float64)
    levels = (np.left_shift(1, np.asarray(bits, dtype=np.int64)) - 1).astype(np.float64)
    scale = np.where(levels > 0, ext / np.maximum(levels, 1.0), 0.0)
    base = np.where(levels > 0, lo, lo + ext / 2)
    return base + np.asarray(codes, dtype=np.float64) * scale


#: Levels of a rotation component's range ends on [-1, 1] (stored as uint16).
UNIT_LEVELS = 65535


def unit_range(lo, hi):
    """``lo`` floored and ``hi`` ceiled onto the uint16 grid of [-1, 1]: ``(lo, ext)`` float64
    exactly as a decoder rebuilds them from their two uint16 (:func:`unit_range_codes`)."""
    lo16 = np.clip(np.floor((np.asarray(lo) + 1) / 2 * UNIT_LEVELS), 0, UNIT_LEVELS)
    hi16 = np.clip(np.ceil((np.asarray(hi) + 1) / 2 * UNIT_LEVELS), 0, UNIT_LEVELS)
    return unit_range_values(lo16, hi16 - lo16)


def unit_range_values(lo16, ext16):
    """(lo, ext) float64 of a rotation range's uint16 codes."""
    lo16, ext16 = np.asarray(lo16, dtype=np.float64), np.asarray(ext16, dtype=np.float64)
    return lo16 * (2.0 / UNIT_LEVELS) - 1.0, ext16 * (2.0 / UNIT_LEVELS)


def unit_range_codes(lo, ext):
    """The uint16 codes (lo16, ext16) of a range made by :func:`unit_range`."""
    lo16 = np.rint((np.asarray(lo) + 1.0) * (UNIT_LEVELS / 2.0))
    return lo16.astype(np.uint16), np.rint(np.asarray(ext) * (UNIT_LEVELS / 2.0)).astype(np.uint16)


def quantise_vectors(values, step, unit=False):
    """Quantise (K, 3) values per component over their range at ``step`` (the largest
    distance between neighbouring levels; the error per component is at most step / 2).
    The range ends are float32, or with ``unit`` (rotation components) on the uint16 grid of
    [-1, 1] (:func:`unit_range`): 12 bytes a track instead of 24.

    Returns
    -------
    VectorCode
    """
    values = np.asarray(values, dtype=np.float64)
    lo, ext = (unit_range if unit else _float32_range)(values.min(axis=0), values.max(axis=0))
    bits = bits_for(ext.astype(np.float64), step)
    levels = (np.left_shift(1, bits) - 1).astype(np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        norm = np.where(levels > 0, (values - lo) / np.where(ext > 0, ext, 1.0), 0.0)
    codes = np.clip(np.rint(norm * levels), 0, levels).astype(np.uint64)
    return VectorCode(lo, ext, bits, codes, step)


def rotation_from_three(three, dropped):
    """Unit quaternions (..., 4) from three stored components (..., 3) and the index of the
    dropped one (broadcast ``...``); the dropped one rebuilt non-negative."""
    three = np.asarray(three, dtype=np.float64)
    w = np.sqrt(np.maximum(1.0 - np.sum(three * three, axis=-1), 0.0))
    dropped = np.broadcast_to(np.asarray(dropped, dtype=np.int64), w.shape)
    q = np.empty(three.shape[:-1] + (4,))
    for c in range(4):           # four masked copies: cheaper than put_along_axis
        hit = dropped == c
        if hit.all():
            q[..., OTHERS[c]] = three
            q[..., c] = w
            break
        if hit.any():
            q[hit] = np.insert(three[hit], c, w[hit], axis=-1)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def quantise_rotations(quats, tol):
    """Quantise a rotation track's keys within ``tol`` (quaternion distance, per key).

    Parameters
    ----------
    quats : (K, 4) float64, unit
    tol : float

    Returns
    -------
    mode : int
        0-3: the component dropped in every key (``fixed``); :data:`PER_KEY`.
    code : VectorCode
        The three stored components (per-key mode: range ``[-1/sqrt 2, 1/sqrt 2]``, the same
        bits for all three).
    dropped : (K,) int
        Each key's dropped component (all ``mode`` in fixed mode).
    """
    quats = np.asarray(quats, dtype=np.float64)
    worst = np.abs(quats).min(axis=0)
    mode = int(np.argmax(worst))
    if worst[mode] >= FIXED_MIN:
        dropped = np.full(len(quats), mode)
        signed = quats * np.sign(quats[:, mode])[:, None]
        three = signed[:, OTHERS[mode]]
        # the rebuilt component's error is |xyz| / w times the stored ones' (norm of dq)
        gain = np.sqrt(1.0 + (1.0 - worst[mode] ** 2) / worst[mode] ** 2)
        return mode, quantise_vectors(three, 2 * tol / (np.sqrt(3) * gain), unit=True), dropped
    dropped = np.argmax(np.abs(quats), axis=1)
    signed = quats * np.sign(quats[np.arange(len(quats)), dropped])[:, None]
    three = np.take_along_axis(signed, OTHERS[dropped], axis=1)
    step = 2 * tol / (np.sqrt(3) * 2.0)      # w >= 1/2, |xyz| <= sqrt(3)/2: gain <= 2
    bits = int(bits_for(2 * _HALF_SQRT2, step))
    lo = np.full(3, -_HALF_SQRT2, dtype=np.float32)
    ext = np.full(3, 2 * _HALF_SQRT2, dtype=np.float32)
    levels = float((1 << bits) - 1)
    codes = np.clip(np.rint((three - lo.astype(np.float64)) / ext.astype(np.float64) * levels),
                    0, levels).astype(np.uint64)
    return PER_KEY, VectorCode(lo, ext, np.full(3, bits), codes), dropped


#: Frames of a segment: a segmented track gives each run of this many frames its own range,
#: a part of the track's range in 1/255ths (ACL's segments).
SEGMENT = 16
#: Bits of a segment's header: per component its range's two ends (8 bits each, in 255ths
#: of the track's range) and its bits (5 bits).
SEGMENT_HEADER_BITS = 3 * (8 + 8 + 5)


def segment_range(lo, ext, a, b):
    """A segment's ``(lo, ext)`` float64 from the track's range and the segment's ends in
    255ths (the same arithmetic in the encoder and the decoder)."""
    lo, ext = np.asarray(lo, dtype=np.float64), np.asarray(ext, dtype=np.float64)
    unit = ext / 255.0
    return lo + np.asarray(a, dtype=np.float64) * unit, \
        (np.asarray(b, dtype=np.float64) - a) * unit


class SegmentCode:
    """A segmented track: per frame segment (G of them) the range ends ``a``, ``b`` (G, 3)
    in 255ths of the track's range and ``bits`` (G, 3); ``codes`` (F, 3) relative to their
    frame's segment; ``values`` (F, 3) decoded; ``cost`` / ``plain``: bits of every frame
    segmented / in the track's range."""

    __slots__ = ("a", "b", "bits", "codes", "values", "cost", "plain")


def segment_vectors(values, code):
    """Quantise (F, 3) values per :data:`SEGMENT`-frame segment within the track's range
    ``code`` (a :class:`VectorCode` of the same values, at the same step); None when a
    component needs more than 31 bits."""
    values = np.asarray(values, dtype=np.float64)
    f = len(values)
    lo, ext = np.asarray(code.lo, np.float64), np.asarray(code.ext, np.float64)
    starts = np.arange(0, f, SEGMENT)
    norm = (values - lo) / np.where(ext > 0, ext, 1.0)
    a = np.clip(np.floor(np.minimum.reduceat(norm, starts, axis=0) * 255), 0, 255)
    b = np.clip(np.ceil(np.maximum.reduceat(norm, starts, axis=0) * 255), 0, 255)
    a = np.where(ext > 0, a, 0)
    b = np.where(ext > 0, np.maximum(b, a), 0)
    seg_lo, seg_ext = segment_range(lo, ext, a, b)
    bits = bits_for(seg_ext, code.step)
    if bits.max(initial=0) > 31:
        return None
    which = np.arange(f) // SEGMENT
    levels = (np.left_shift(1, bits) - 1).astype(np.float64)[which]
    span = seg_ext[which]
    with np.errstate(divide="ignore", invalid="ignore"):
        normed = np.where(levels > 0, (values - seg_lo[which]) / np.where(span > 0, span, 1), 0)
    out = SegmentCode()
    out.a, out.b, out.bits = a.astype(np.uint8), b.astype(np.uint8), bits
    out.codes = np.clip(np.rint(normed * levels), 0, levels).astype(np.uint64)
    out.values = dequantise_vectors(seg_lo[which], seg_ext[which], bits[which], out.codes)
    out.cost = int(bits[which].sum()) + len(starts) * SEGMENT_HEADER_BITS
    out.plain = f * int(np.sum(code.bits))
    return out
