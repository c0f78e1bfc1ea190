"""One track of one clip, from its values at every frame to what is stored: dropped, stored
once, or quantised and key-reduced (for rigedit's format or for glTF)."""
from __future__ import annotations

import numpy as np

from .constant import ANIMATED, CONSTANT, classify
from .layout import EncodedTrack
from .quantise import (OTHERS, PER_KEY, VectorCode, quantise_rotations, quantise_vectors,
                       rotation_from_three, segment_vectors)
from .reduce import reduce_keys
from .reduce_cubic import reduce_cubic

__all__ = ["QUANTISE_SHARE", "encode_tracks", "gltf_tracks", "gltf_values", "dense_is_cheaper"]

#: Part of a track's tolerance its quantisation may take; key reduction gets the rest (it
#: measures the quantised values, so the two together stay within the tolerance). One bit
#: more per component halves the quantisation error; the share was picked by measurement
#: (docs/compression.md).
QUANTISE_SHARE = 0.8
#: A track is segmented when that takes under this part of its unsegmented bits (at every
#: frame, headers counted): key reduction then keeps fewer keys a segment header pays for.
SEGMENT_GAIN = 0.9
#: Frames a clip needs before its tracks are also tried with Catmull-Rom keys.
MIN_CUBIC_FRAMES = 4
#: Try Catmull-Rom keys at all (off: every track linear; the benchmark measures the gain).
CUBIC_KEYS = True


def _classified(values, rest, tol, rotation, measured=None):
    kind, value = classify(values, rest, tol, rotation, measured)
    if len(values) < 2 and kind == ANIMATED:
        kind, value = CONSTANT, values[0].astype(np.float32)
    return kind, value


def _groups(animated, among=None):
    """Indices of ``animated`` (of those in ``among``, all by default) by kind: rotations,
    then vectors (those there are)."""
    among = range(len(animated)) if among is None else among
    for rotation in (True, False):
        group = [i for i in among if animated[i][3] == rotation]
        if group:
            yield rotation, group


def _stacked(animated, group):
    """The reducers' arrays of tracks ``group``: references (T, F, C), decoded values
    (T, F, C), tolerances (T,) and the half-frame references (T, F - 1, C), None unless every
    track has them."""
    mids = [animated[i][4] if len(animated[i]) > 4 else None for i in group]
    return (np.stack([animated[i][0] for i in group]),
            np.stack([animated[i][1] for i in group]),
            np.array([animated[i][2] for i in group]),
            None if any(m is None for m in mids) else np.stack(mids))


def _reduce_groups(grid, animated):
    """Reduce the keys of many tracks at once, one :func:`reduce_keys` call per kind
    (rotations, vectors). ``animated``: list of (values (F, C), decoded (F, C), tol,
    rotation[, values at the half-frames (F - 1, C)]); returns the kept frame indices of
    each."""
    keys = [None] * len(animated)
    for rotation, group in _groups(animated):
        ref, decoded, tol, mids = _stacked(animated, group)
        keep = reduce_keys(grid, ref, decoded, tol, rotation, mid_reference=mids)
        for row, i in zip(keep, group):
            keys[i] = np.flatnonzero(row)
    return keys


def _fewest_keys(grid, animated, allow):
    """Per track, ``(keys, cubic)``: Catmull-Rom keys (:mod:`.reduce_cubic`, checked at the
    half-frames too) where ``allow`` says so and they are fewer than the linear ones and
    hold, else the linear keys. A track without its half-frame values (an ``animated`` item
    of 4, or None there) and every track of a clip of a handful of frames is linear. (Tracks
    whose linear keys keep most frames are tried too: on a smooth clip at a tight bound the
    cubic kept 85 of 297.)"""
    linear = _reduce_groups(grid, animated)
    out = [(k, False) for k in linear]
    if len(grid) < MIN_CUBIC_FRAMES or not CUBIC_KEYS:
        return out
    tried = [i for i, a in enumerate(animated) if len(a) > 4 and a[4] is not None
             and allow[i]]
    for rotation, group in _groups(animated, tried):
        ref, decoded, tol, mids = _stacked(animated, group)
        keep, ok = reduce_cubic(grid, ref, decoded, tol, rotation, mids)
        for row, good, i in zip(keep, ok, group):
            cubic = np.flatnonzero(row)
            if good and len(cubic) < len(linear[i]):
                out[i] = (cubic, True)
    return out


def encode_tracks(items, grid, mids=None, cubic=None):
    """The stored form of tracks of one clip for rigedit's format, all reduced together.

    Parameters
    ----------
    items : list of (joint, channel, values (F, C), rest (C,), tol[, measured])
        Each track at every frame, its joint's rest value, its tolerance in the channel's
        units (quaternion distance for rotations) and optionally its
        :func:`~rigedit.compression.constant.spread`.
    grid : (F,) float64
        The frame times as decoded.
    mids : list of (F - 1, C) float64 or None, optional
        Each track at the half-frames (:func:`~rigedit.compression.reduce_cubic.half_frames`):
        given, they are held there too where keys can (:mod:`.reduce`), and a track may take
        Catmull-Rom keys (checked there as well); else (None) its keys are linear.
    cubic : list of bool, optional
        Per item, whether it may take Catmull-Rom keys (all may, by default).

    Returns
    -------
    list of EncodedTrack or None
        None: the track is the rest value (not stored).
    """
    out, animated, codes, allow = [None] * len(items), [], [], []
    for i, (joint, channel, values, rest, tol, *measured) in enumerate(items):
        rotation = channel == "rotation"
        kind, value = _classified(values, rest, tol, rotation, *measured)
        if kind == CONSTANT:
            out[i] = EncodedTrack(joint, channel, value=value)
        if kind != ANIMATED:
            continue
        quant = QUANTISE_SHARE * tol
        segments = None
        if rotation:
            mode, code, dropped = quantise_rotations(values, quant)
            if mode != PER_KEY:
                signed = values * np.sign(values[:, mode])[:, None]
                segments = _segmented(signed[:, OTHERS[mode]], code)
            three = code.values() if segments is None else segments.values
            decoded = rotation_from_three(three, dropped)
        else:
            mode, dropped = 0, None
            code = quantise_vectors(values, 2 * quant / np.sqrt(3))
            segments = _segmented(values, code)
            decoded = code.values() if segments is None else segments.values
        animated.append((values, decoded, tol, rotation) if mids is None else
                        (values, decoded, tol, rotation, mids[i]))
        codes.append((i, mode, code, dropped, segments))
        allow.append(True if cubic is None else cubic[i])
    for (keys, cubic_keys), (i, mode, code, dropped, segments) in zip(
            _fewest_keys(grid, animated, allow), codes):
        joint, channel = items[i][:2]
        stored = code.codes if segments is None else segments.codes
        out[i] = EncodedTrack(joint, channel, keys=keys, mode=mode,
                              code=VectorCode(code.lo, code.ext, code.bits, stored[keys]),
                              dropped=None if dropped is None else dropped[keys],
                              segments=segments, cubic=cubic_keys)
    return out


def _segmented(values, code):
    """The track's :class:`SegmentCode` when segment ranges take fewer bits at every frame
    (by more than the segment headers), else None."""
    segments = segment_vectors(values, code)
    if segments is None or segments.cost >= SEGMENT_GAIN * segments.plain:
        return None
    return segments


def gltf_values(values, rotation):
    """What a glTF file holds of values (F, C): float32 vectors; rotations hemisphere-aligned
    and on the normalised int16 grid (``round(v * 32767) / 32767``)."""
    if not rotation:
        return values.astype(np.float32).astype(np.float64)
    q = values.copy()
    dots = np.sum(q[1:] * q[:-1], axis=1)
    q[1:] *= np.cumprod(np.where(dots < 0, -1.0, 1.0))[:, None]
    return np.round(q * 32767.0) / 32767.0


def gltf_tracks(items, grid, mids=None):
    """The reduced keys of tracks for glTF, items and ``mids`` as :func:`encode_tracks`
    (linear keys only): each ``(times (K,), values (K, C))`` (float32 times, values as
    :func:`gltf_values`; one key for a constant track), or None (the rest)."""
    out, animated, stored_all = [None] * len(items), [], []
    for i, (joint, channel, values, rest, tol, *measured) in enumerate(items):
        rotation = channel == "rotation"
        kind, value = _classified(values, rest, tol, rotation, *measured)
        if kind == CONSTANT:
            out[i] = grid[:1], gltf_values(value[None].astype(np.float64), rotation)
        if kind != ANIMATED:
            continue
        stored = gltf_values(values, rotation)
        decoded = stored / np.linalg.norm(stored, axis=1, keepdims=True) if rotation \
            else stored
        animated.append((values, decoded, tol, rotation) if mids is None else
                        (values, decoded, tol, rotation, mids[i]))
        stored_all.append((i, stored))
    every = np.arange(len(grid))
    for keys, (i, stored), a in zip(_reduce_groups(grid, animated), stored_all, animated):
        if dense_is_cheaper(len(keys), len(grid), a[3]):
            keys = every
        out[i] = grid[keys], stored[keys]
    return out


def dense_is_cheaper(keys, frames, rotation):
    """Whether a glTF track of ``keys`` reduced keys costs more than keying every frame: its
    own key times cost 4 bytes a key, while every frame's times are one accessor that all
    such tracks share (int16 rotations: 8 bytes a key, float32 vectors 12)."""
    value = 8 if rotation else 12
    return keys * (value + 4) > frames * value
