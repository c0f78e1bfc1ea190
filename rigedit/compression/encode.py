"""One track of one clip, from its values at every frame to what is stored: dropped, stored
once, or quantised and key-reduced (for rigedit's format or for glTF)."""
from __future__ import annotations

import numpy as np

from .constant import ANIMATED, CONSTANT, OMITTED, classify
from .layout import EncodedTrack
from .quantise import VectorCode, quantise_rotations, quantise_vectors, rotation_from_three
from .reduce import reduce_keys

__all__ = ["QUANTISE_SHARE", "encode_track", "gltf_track"]

#: Part of a track's tolerance its quantisation may take; key reduction gets the rest (it
#: measures the quantised values, so the two together stay within the tolerance). One bit
#: more per component halves the quantisation error; the share was picked by measurement
#: (docs/compression.md).
QUANTISE_SHARE = 0.8


def _classified(values, rest, tol, rotation):
    kind, value = classify(values, rest, tol, rotation)
    if len(values) < 2 and kind == ANIMATED:
        kind, value = CONSTANT, values[0].astype(np.float32)
    return kind, value


def encode_track(joint, channel, values, rest, tol, grid):
    """The stored form of one track for rigedit's format.

    Parameters
    ----------
    joint : int
    channel : str
    values : (F, C) float64
        The track at every frame.
    rest : (C,) float64
    tol : float
        In the channel's units (quaternion distance for rotations).
    grid : (F,) float64
        The frame times as decoded.

    Returns
    -------
    EncodedTrack or None
        None: the track is the rest value (not stored).
    """
    rotation = channel == "rotation"
    kind, value = _classified(values, rest, tol, rotation)
    if kind == OMITTED:
        return None
    if kind == CONSTANT:
        return EncodedTrack(joint, channel, value=value)
    quant = QUANTISE_SHARE * tol
    if rotation:
        mode, code, dropped = quantise_rotations(values, quant)
        decoded = rotation_from_three(code.values(), dropped)
    else:
        mode, dropped = 0, None
        code = quantise_vectors(values, 2 * quant / np.sqrt(3))
        decoded = code.values()
    keep = reduce_keys(grid, values[None], decoded[None], np.array([tol]), rotation)[0]
    keys = np.flatnonzero(keep)
    return EncodedTrack(joint, channel, keys=keys, mode=mode,
                        code=VectorCode(code.lo, code.ext, code.bits, code.codes[keys]),
                        dropped=None if dropped is None else dropped[keys])


def gltf_values(values, rotation):
    """What a glTF file holds of values (F, C): float32 vectors; rotations hemisphere-aligned
    and on the normalised int16 grid (``round(v * 32767) / 32767``)."""
    if not rotation:
        return values.astype(np.float32).astype(np.float64)
    q = values.copy()
    dots = np.sum(q[1:] * q[:-1], axis=1)
    q[1:] *= np.cumprod(np.where(dots < 0, -1.0, 1.0))[:, None]
    return np.round(q * 32767.0) / 32767.0


def gltf_track(channel, values, rest, tol, grid):
    """The reduced keys of one track for glTF: ``(times (K,), values (K, C))`` (float32
    times, values as :func:`gltf_values`), or ``("constant", value)``, or None (the rest)."""
    rotation = channel == "rotation"
    kind, value = _classified(values, rest, tol, rotation)
    if kind == OMITTED:
        return None
    stored = gltf_values(values, rotation)
    if kind == CONSTANT:
        return grid[:1], gltf_values(value[None].astype(np.float64), rotation)
    decoded = stored / np.linalg.norm(stored, axis=1, keepdims=True) if rotation else stored
    keep = reduce_keys(grid, values[None], decoded[None], np.array([tol]), rotation)[0]
    return grid[keep], stored[keep]
