"""BVH has no units: the units a file may be in, and the guess of one from the figure's size.

Shared by the reader (:mod:`rigedit.io.bvh`, which guesses) and the writer
(:mod:`rigedit.io.bvh_write`, which warns when a figure written would be guessed wrong).
"""
from __future__ import annotations

import numpy as np

__all__ = ["UNITS", "TYPICAL_HEIGHT", "HUMAN_SIZE", "BvhUnitsWarning", "guess_unit",
           "believable"]

#: Units a BVH figure may be written in: name -> metres per unit. "CMU" is the unit of the
#: Carnegie Mellon mocap library's BVH conversions (its ASF "length 0.45": 1/0.45 inch).
UNITS = {"metres": 1.0, "centimetres": 0.01, "millimetres": 0.001, "inches": 0.0254,
         "CMU units (1/0.45 inch)": 0.0254 / 0.45}
#: The figure height a guess aims at (an adult human), metres.
TYPICAL_HEIGHT = 1.7
#: The sizes (largest extent, metres) a human figure may have: outside, a guess is flagged.
HUMAN_SIZE = (1.2, 2.2)


class BvhUnitsWarning(UserWarning):
    """A BVH file's unit was guessed (no ``scale`` given)."""


def guess_unit(size):
    """The unit under which a figure ``size`` file units across is an adult's size.

    Parameters
    ----------
    size : float
        The figure's largest extent (height, or arm span in a T pose), carrier roots left
        out.

    Returns
    -------
    name : str
    metres_per_unit : float

    Notes
    -----
    The unit that makes the figure 1.2-2.2 m (:data:`HUMAN_SIZE`) when there is one (the
    range is narrower than the ratio of any two units in :data:`UNITS`, so there is at most
    one): a figure 120-220 units across reads as centimetres, 1.2-2.2 as metres, 1200-2200
    as millimetres, 47-87 as inches, 21-39 as CMU units. Otherwise the unit whose figure is
    nearest 1.7 m, which :func:`believable` then reports as not a human's size.
    """
    if not size > 0:
        return "metres", 1.0
    human = [u for u in UNITS if believable(size * UNITS[u])]
    name = human[0] if len(human) == 1 else \
        min(UNITS, key=lambda u: abs(np.log(size * UNITS[u] / TYPICAL_HEIGHT)))
    return name, UNITS[name]


def believable(metres):
    """Whether a figure ``metres`` across is a human's size (:data:`HUMAN_SIZE`)."""
    return HUMAN_SIZE[0] <= metres <= HUMAN_SIZE[1]
