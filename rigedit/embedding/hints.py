"""Hints: joints the user pins (as Mixamo asks for the chin, wrists, elbows, knees and groin).

A hint is a template joint's position in the mesh, in the embedding's frame (the caller turns
points given in the mesh file's coordinates). The search then places the other joints around
the hinted ones:

* a hinted **reduced** joint (a hand, a foot, the hips) may only go near its hint: its
  unary cost grows with the squared distance in units of ``unit`` (5% of the scaled
  template), ``W_HINT`` per unit;
* a hinted **inner** joint of a reduced chain (an elbow, a knee, a spine joint) says how
  long the chain's two halves are: the reduced bone from a to b costs the log ratios of
  |hint - a| and |b - hint| to the template's two half-chords (scaled), squared, plus the
  turn of each half from the template's direction, like a bone of its own;
* every hinted joint is then pinned in the refinement and put exactly at its hint; a hinted
  carried joint (a jaw, a toe) moves its carried joints below it with it.
"""
from __future__ import annotations

import numpy as np

from .penalties import W_DIRECTION, W_LENGTH

__all__ = ["HintError", "check_hints", "hint_unary", "hint_pair", "W_HINT", "W_HINT_INNER"]

#: A hinted reduced joint one unit (5% of the scaled template) from its hint costs this much:
#: ten times a clearly wrong bone, so the search honours the hint before any prior.
W_HINT = 10.0
#: A hinted inner joint's two half-chains, as a bone's length and direction terms, times
#: this: twice a bone (the user said where the elbow is; the template only guesses).
W_HINT_INNER = 1.0
#: The halves' turn from the template's direction, per (1 - cos): a tenth of a bone's
#: (:data:`.penalties.W_DIRECTION`). Weak on purpose: a hinted knee in a crouch has its shin
#: 30 degrees off the template's, and a bone's direction term there put the foot under the
#: knee, 9% of the height forward of the mesh's; the reduced bone's own chord term stays.
W_HALF_DIRECTION = 0.1 * W_DIRECTION
#: A hint may lie this many distance-field cells outside the mesh (a point picked on the
#: skin, a thin part the grid does not resolve); that far or further out is an error.
OUTSIDE_CELLS = 1.0


class HintError(ValueError):
    """A hint names no joint of the template, or lies outside the mesh."""


def check_hints(hints, names, field=None):
    """Hints by joint name -> by template index, checked.

    Parameters
    ----------
    hints : dict[str, (3,) float] or None
    names : list of str
        The template's joint names.
    field : DistanceField, optional
        The mesh's: a hint more than ``OUTSIDE_CELLS`` cells outside it is refused.

    Returns
    -------
    dict[int, (3,) float64]

    Raises
    ------
    HintError
        Naming the joint: unknown, not three finite numbers, or outside the mesh.
    """
    out = {}
    index = {n: i for i, n in enumerate(names)}
    for name, point in (hints or {}).items():
        if name not in index:
            near = [n for n in names if n.lower() == str(name).lower()]
            also = f" (did you mean {near[0]}?)" if near else ""
            raise HintError(f"hint for joint {name!r}: the template has no such joint{also}")
        try:
            p = np.asarray(point, dtype=np.float64).reshape(3)
        except (TypeError, ValueError):
            raise HintError(f"hint for joint {name!r}: expected x, y, z, got {point!r}") from None
        if not np.all(np.isfinite(p)):
            raise HintError(f"hint for joint {name!r}: expected finite x, y, z, got {point!r}")
        if field is not None:
            depth = float(field(p[None])[0])
            if depth <= -OUTSIDE_CELLS * field.h:   # the field holds -h far out
                # no coordinates: the caller may have turned the user's point into this frame
                raise HintError(f"hint for joint {name!r} is outside the mesh (expected a "
                                "point inside the body, or on its skin)")
        out[index[name]] = p
    return out


def hint_unary(points, hint, unit):
    """(N,) cost of a hinted reduced joint at each graph vertex ``points`` (N, 3): 0 at the
    vertex nearest the hint (the joint goes exactly there afterwards; the cost measures the
    fit of the rest, not how far the graph's sparse vertices are from the hint)."""
    d2 = np.sum((points - hint) ** 2, axis=1)
    return W_HINT * (d2 - d2.min()) / (unit * unit)


def hint_pair(points, hint, rest_a, rest_h, rest_b, scale):
    """(N, N) cost of a reduced bone a (rows) -> b (columns) whose chain has a hinted inner
    joint at ``hint`` (template positions ``rest_a``, ``rest_h``, ``rest_b``).

    Both half-chains are scored as bones (:mod:`.penalties`' length and direction terms: log
    length ratio squared and 1 - cos of the turn from the template's direction), so the
    result is separable: a term on a plus a term on b.
    """
    def half(start, end, tmpl):
        d = end - start                                      # (N, 3)
        length = np.linalg.norm(d, axis=1)
        t_len = max(float(np.linalg.norm(tmpl)), 1e-12)
        with np.errstate(divide="ignore", invalid="ignore"):
            cos = d @ (tmpl / t_len) / length
            cost = (2.0 * W_LENGTH * np.log(length / (scale * t_len)) ** 2
                    + W_HALF_DIRECTION * (1.0 - cos))
        return np.where(np.isfinite(cost), cost, np.inf)
    first = half(points, hint[None, :], rest_h - rest_a)    # a -> hint, per a
    second = half(hint[None, :], points, rest_b - rest_h)   # hint -> b, per b
    return W_HINT_INNER * (first[:, None] + second[None, :])
