"""Rigs with morph targets built in code, for the editor and UI tests (numpy only)."""
from __future__ import annotations

import numpy as np

from rigedit.model.morph import MorphTargets


def add_targets(rig, names=("bulge", "squash"), seed=0):
    """Give ``rig`` two synthetic morph targets and return it.

    ``names[0]`` pushes the vertices of the top fifth of the mesh outwards from its vertical
    axis (by a tenth of the height at weight 1); ``names[1]`` flattens the bottom third
    towards the floor. Each moves only its part of the mesh (sparse), neither has normal
    deltas.
    """
    v = rig.vertices
    up = 1 if rig.up == "y" else 2
    lo, hi = v[:, up].min(), v[:, up].max()
    height = hi - lo or 1.0
    deltas = np.zeros((2, len(v), 3), np.float32)
    top = v[:, up] > hi - 0.2 * height
    centre = v[top].mean(axis=0)
    out = v[top] - centre
    out[:, up] = 0.0
    length = np.linalg.norm(out, axis=1, keepdims=True)
    deltas[0, top] = 0.1 * height * np.divide(out, length, out=np.zeros_like(out),
                                              where=length > 0)
    low = v[:, up] < lo + height / 3
    deltas[1, low, up] = -0.5 * (v[low, up] - lo)
    rig.morphs = MorphTargets(tuple(names), deltas)
    rig.bind(rig.binding.indices, rig.binding.weights)
    return rig


def quadruped_with_targets():
    """The bundled quadruped with :func:`add_targets`' two targets ("bulge" at the antlers'
    height, "squash" at the hooves)."""
    import rigedit

    return add_targets(rigedit.load_rig("quadruped"))
