"""One stroke of the weight brush: a working copy of the skin weights, painted dab by dab,
that becomes one undo step when the mouse is released.

The maths of a dab is :mod:`rigedit.binding.weight_paint`'s; the mouse handling that makes
strokes is :class:`~rigedit.ui.weight_brush.WeightBrush`'s. No Qt or VTK here.
"""
from __future__ import annotations

import numpy as np

from ..binding.weight_paint import brush_vertices, joint_column, paint, paint_mirrored

__all__ = ["WeightStroke"]


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
