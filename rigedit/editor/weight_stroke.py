"""One stroke of the weight brush: a working copy of the skin weights, painted dab by dab,
that becomes one undo step when the mouse is released.

The maths of a dab is :mod:`rigedit.binding.weight_paint`'s (its brush modes are
:data:`MODES`); the mouse handling that makes strokes is
:class:`~rigedit.ui.weight_brush.WeightBrush`'s. :class:`BrushTables` keeps what dabs need
beyond the weights. No Qt or VTK here.
"""
from __future__ import annotations

import numpy as np

from ..binding.weight_paint import (MODES, brush_vertices, joint_column, mirror_vertices,
                                    paint, paint_mirrored, vertex_adjacency)
from .mirror import side_axis

__all__ = ["WeightStroke", "BrushTables", "MODES"]


class WeightStroke:
    """The stroke under way on one joint's weights.

    Parameters
    ----------
    document : Document
        Its rig's binding is copied; :meth:`commit` writes the result back.
    joint : int
        The joint painted.

    Attributes
    ----------
    joint : int
    indices : (V, K) int
    weights : (V, K) float64
        The working influences, painted by each :meth:`dab`.
    dabs : int
        Dabs painted so far.
    """

    def __init__(self, document, joint):
        self.document = document
        self.joint = joint
        self.rig = document.rig
        self.binding = self.rig.binding
        self.indices = self.binding.indices.copy()
        self.weights = self.binding.weights.copy()
        self.dabs = 0

    def dab(self, points, point, radius, mode, strength, value, locked, adjacency=None,
            mirror=None):
        """Paint the vertices within ``radius`` of ``point`` with a smooth falloff.

        Parameters
        ----------
        points : (V, 3) float
            The surface as shown (the skinned vertices).
        point : (3,) float
            The dab's centre on that surface.
        radius : float
            Scene units.
        mode, strength, value :
            The brush settings (:func:`rigedit.binding.weight_paint.paint`).
        locked : iterable of int
            Joints whose weights must not change.
        adjacency : sparse (V, V), optional
            Vertex adjacency, needed by the ``"smooth"`` mode.
        mirror : (V,) int, optional
            Each vertex's mirror image (-1: none): paint both sides
            (:func:`~rigedit.binding.weight_paint.paint_mirrored`).

        Returns
        -------
        painted : bool
            False when no vertex was within reach.
        """
        verts, factors = brush_vertices(points, point, radius)
        if len(verts) == 0:
            return False
        sk = self.document.skeleton
        options = dict(mode=mode, strength=strength, value=value, locked=sorted(locked),
                       fallback=int(sk.parents[self.joint]), adjacency=adjacency)
        args = (self.indices, self.weights, len(sk), self.joint, verts, factors)
        if mirror is not None:
            self.indices, self.weights = paint_mirrored(*args, mirror, self.document.mirror,
                                                        **options)
        else:
            self.indices, self.weights = paint(*args, **options)
        self.dabs += 1
        return True

    def column(self):
        """(V,) float64: the painted joint's weight per vertex in the working copy."""
        return joint_column(self.indices, self.weights, self.joint)

    def commit(self):
        """Make the stroke one undo step (:meth:`Document.set_weights`).

        Returns
        -------
        message : str or None
            What happened, for the status bar; None when the stroke changed nothing.
        """
        d = self.document
        if d.rig is not self.rig or d.rig.binding is not self.binding:
            return "Stroke dropped: the weights changed while painting"
        b = self.binding
        if np.array_equal(self.indices, b.indices) and np.array_equal(self.weights, b.weights):
            return None
        name = d.skeleton.names[self.joint]
        d.set_weights(self.indices, self.weights, label=f"Paint {name}")
        return f"Painted {name} ({self.dabs} dabs); Ctrl+Z undoes the stroke"


class BrushTables:
    """What dabs need beyond the weights, computed once per rig and kept while it is the
    document's (the first dab of a smooth or mirrored stroke pays for it, the others not).

    Parameters
    ----------
    document : Document
    """

    def __init__(self, document):
        self.document = document
        self._tables = {}

    def clear(self):
        """Forget the tables (a rig was opened: the next dab computes them again)."""
        self._tables = {}

    def _table(self, key, make):
        rig = self.document.rig
        if self._tables.get("rig") is not rig:
            self._tables = {"rig": rig}
        if key not in self._tables:
            self._tables[key] = make(rig)
        return self._tables[key]

    def adjacency(self):
        """(V, V) sparse: the rig's vertex adjacency (the ``"smooth"`` mode's)."""
        return self._table("adjacency", lambda rig: vertex_adjacency(rig.faces,
                                                                      len(rig.vertices)))

    def mirror(self):
        """(V,) int: each rest vertex's mirror image across the skeleton's left-right axis
        (-1: none), for a mirrored stroke."""
        d = self.document
        axis = side_axis(d.skeleton, d.mirror)
        return self._table(("mirror", axis), lambda rig: mirror_vertices(rig.vertices, axis))
