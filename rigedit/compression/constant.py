"""Drop what does not move: a track within its tolerance of the rest value is not stored at
all, one within its tolerance of a single value is stored once (float32)."""
from __future__ import annotations

import numpy as np

__all__ = ["OMITTED", "CONSTANT", "ANIMATED", "distance", "spread", "classify"]

OMITTED, CONSTANT, ANIMATED = "omitted", "constant", "animated"


def distance(values, target, rotation):
    """Per key distance (K,) of values (K, C) to ``target`` (C,) or (K, C); rotations compare
    q and -q as the same."""
    d = np.linalg.norm(values - target, axis=-1)
    if rotation:
        d = np.minimum(d, np.linalg.norm(values + target, axis=-1))
    return d


def representative(values, rotation):
    """One float32 value standing for a track's keys (K, C): the middle of the range, for a
    rotation the normalised mean of the keys on the first key's hemisphere."""
    if rotation:
        signs = np.where(values @ values[0] < 0, -1.0, 1.0)
        mean = (values * signs[:, None]).mean(axis=0)
        return (mean / np.linalg.norm(mean)).astype(np.float32)
    return ((values.min(axis=0) + values.max(axis=0)) / 2).astype(np.float32)


def spread(values, rest, rotation):
    """What classifying a track needs, measured once: ``(largest distance to the rest value,
    largest distance to the stored value, the stored value (C,) float32)``."""
    to_rest = float(distance(values, rest, rotation).max())
    value = representative(values, rotation)
    stored = value.astype(np.float64)
    if rotation:
        stored = stored / np.linalg.norm(stored)
    return to_rest, float(distance(values, stored, rotation).max()), value


def classify(values, rest, tol, rotation, measured=None):
    """What a track needs: ``(OMITTED, None)``, ``(CONSTANT, value (C,) float32)`` or
    ``(ANIMATED, None)``.

    Parameters
    ----------
    values : (K, C) float64
        The track sampled at the clip's frames.
    rest : (C,) float64
        The joint's rest value (what a decoder gives a track that is not stored).
    tol : float
        In the channel's units.
    measured : tuple, optional
        :func:`spread` of the same track (so a track classified at many tolerances is
        measured once).
    """
    to_rest, to_value, value = spread(values, rest, rotation) if measured is None else measured
    if to_rest <= tol:
        return OMITTED, None
    if to_value <= tol:
        return CONSTANT, value
    return ANIMATED, None
