"""Morph targets (glTF morph targets, FBX blend shapes): per-vertex displacements in bind space.

A morphed rest point is ``rest + sum_m w_m * deltas[m]`` (glTF 2.0, "Morph Targets"); the
skinning pass then deforms that point as it would the rest point. Only the targets with a
non-zero weight cost anything: with every weight 0, :meth:`MorphTargets.apply` returns None
and the caller skins the plain rest points.

Each target keeps, next to its dense (V, 3) deltas, the rows it actually moves (a face shape
moves a few hundred of a body's vertices), so applying a target costs its moved rows only.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

__all__ = ["MorphTargets", "MorphedRest"]


@dataclass(eq=False)
class MorphTargets:
    """The morph targets of one mesh.

    Attributes
    ----------
    names : tuple of str, (M,)
        Unique target names.
    deltas : (M, V, 3) float32
        Position displacements in bind (model) space.
    normal_deltas : (M, V, 3) float32 or None
        Normal displacements (added to the rest normals, renormalised by the skinning pass).
    default_weights : (M,) float64 or None
        The weights when nothing sets them (glTF ``mesh.weights``); zeros if None.
    """

    names: tuple
    deltas: np.ndarray
    normal_deltas: Optional[np.ndarray] = None
    default_weights: Optional[np.ndarray] = None
    # per target: the vertex rows it moves (int64) and their deltas, built once
    _rows: list = field(default_factory=list, init=False, repr=False)
    _sparse: list = field(default_factory=list, init=False, repr=False)
    _sparse_n: list = field(default_factory=list, init=False, repr=False)
    _slot: dict = field(default_factory=dict, init=False, repr=False)   # name -> index

    def __post_init__(self):
        self.names = tuple(str(n) for n in self.names)
        self._slot = {name: m for m, name in enumerate(self.names)}
        if len(self._slot) != len(self.names):
            raise ValueError(f"morph target names are not unique: {self.names}")
        self.deltas = np.ascontiguousarray(self.deltas, dtype=np.float32)
        if self.deltas.ndim != 3 or self.deltas.shape[2] != 3 \
                or self.deltas.shape[0] != len(self.names):
            raise ValueError(f"morph deltas must be ({len(self.names)}, V, 3), "
                             f"not {self.deltas.shape}")
        if not np.isfinite(self.deltas).all():
            raise ValueError("morph deltas are not all finite")
        if self.normal_deltas is not None:
            self.normal_deltas = np.ascontiguousarray(self.normal_deltas, dtype=np.float32)
            if self.normal_deltas.shape != self.deltas.shape:
                raise ValueError(f"morph normal deltas must be {self.deltas.shape}, "
                                 f"not {self.normal_deltas.shape}")
            if not np.isfinite(self.normal_deltas).all():
                raise ValueError("morph normal deltas are not all finite")
        if self.default_weights is None:
            self.default_weights = np.zeros(len(self.names))
        self.default_weights = np.asarray(self.default_weights, dtype=np.float64).reshape(-1)
        if self.default_weights.shape != (len(self.names),):
            raise ValueError(f"morph default weights must be ({len(self.names)},), "
                             f"not {self.default_weights.shape}")
        self._index_rows()

    def _index_rows(self):
        """Per target the rows it moves (position or normal), and their deltas."""
        self._rows, self._sparse, self._sparse_n = [], [], []
        for m in range(len(self.names)):
            moved = np.any(self.deltas[m] != 0, axis=1)
            if self.normal_deltas is not None:
                moved |= np.any(self.normal_deltas[m] != 0, axis=1)
            rows = np.flatnonzero(moved)
            self._rows.append(rows)
            self._sparse.append(np.ascontiguousarray(self.deltas[m][rows]))
            self._sparse_n.append(None if self.normal_deltas is None else
                                  np.ascontiguousarray(self.normal_deltas[m][rows]))

    # ------------------------------------------------------------------ facts
    @property
    def count(self) -> int:
        """M, the number of targets."""
        return len(self.names)

    @property
    def n_vertices(self) -> int:
        """V, the vertices each target displaces."""
        return int(self.deltas.shape[1])

    def index(self, name) -> int:
        """The position of target ``name`` in :attr:`names` (KeyError if none)."""
        return self._slot[name]

    def moved_rows(self, m) -> np.ndarray:
        """(n,) int64: the vertices target ``m`` moves."""
        return self._rows[m]

    def sparse_target(self, m):
        """Target ``m`` as the rows it moves: ``rows`` (n,) int64, position deltas (n, 3)
        float32 and normal deltas (n, 3) float32 or None."""
        return self._rows[m], self._sparse[m], self._sparse_n[m]

    def weights_array(self, weights=None) -> np.ndarray:
        """(M,) float64 weights from ``weights``: None (the defaults), a sequence of M
        numbers, or a mapping name -> weight (names not given keep their default; names
        that are not targets are ignored, so a clip made for another rig does no harm)."""
        if weights is None:
            return self.default_weights.copy()
        if isinstance(weights, dict):
            out = self.default_weights.copy()
            slot = self._slot
            for name, w in weights.items():
                m = slot.get(name)
                if m is not None:
                    out[m] = float(w)
            return out
        out = np.asarray(weights, dtype=np.float64).reshape(-1)
        if out.shape != (self.count,):
            raise ValueError(f"expected {self.count} morph weights, got {out.shape}")
        return out

    def active(self, weights) -> np.ndarray:
        """(A,) int64: the targets whose weight is not 0 (and that move something)."""
        w = self.weights_array(weights)
        return np.array([m for m in np.flatnonzero(w != 0) if len(self._rows[m])],
                        dtype=np.int64)

    # ------------------------------------------------------------------ apply
    def apply(self, weights, out=None):
        """The displacement sum ``sum_m w_m * deltas[m]``.

        Parameters
        ----------
        weights : None, (M,) sequence or dict name -> float
            See :meth:`weights_array`.
        out : (V, 3) float32, optional
            Buffer written in place (zeroed first) and returned.

        Returns
        -------
        (V, 3) float32 or None
            None when no target is active (all weights 0): no time is spent and the caller
            uses the rest points as they are.
        """
        return self._apply(weights, out, self._sparse)

    def apply_normals(self, weights, out=None):
        """The normal displacement sum, as :meth:`apply` (None also when the targets have no
        normal deltas)."""
        if self.normal_deltas is None:
            return None
        return self._apply(weights, out, self._sparse_n)

    def _apply(self, weights, out, sparse):
        w = self.weights_array(weights)
        act = [m for m in np.flatnonzero(w != 0) if len(self._rows[m])]
        if not act:
            return None
        if out is None:
            out = np.zeros((self.n_vertices, 3), dtype=np.float32)
        else:
            out[...] = 0.0
        for m in act:
            # rows are unique within one target, so the fancy-index add is exact
            out[self._rows[m]] += np.float32(w[m]) * sparse[m]
        return out

    def morphed(self, rest, weights, out=None):
        """(V, 3) float32 ``rest + apply(weights)``; ``rest`` itself (not a copy) when no
        target is active."""
        disp = self.apply(weights)
        if disp is None:
            return rest
        if out is None:
            out = np.empty((self.n_vertices, 3), dtype=np.float32)
        np.add(rest, disp, out=out, casting="unsafe")
        return out

    def subset(self, vertex_rows):
        """The targets restricted to the vertices ``vertex_rows`` (a mesh split or merged)."""
        rows = np.asarray(vertex_rows, dtype=np.int64)
        return MorphTargets(self.names, self.deltas[:, rows],
                            None if self.normal_deltas is None else self.normal_deltas[:, rows],
                            self.default_weights.copy())


class MorphedRest:
    """The rest points (and normals) a skinning pass reads, with the current weights' morphs.

    Kept by :class:`rigedit.model.skinning.SkinBinding`. With no active target the plain
    rest arrays are handed out as they are (no copy, no time). Otherwise one float32 buffer
    per array holds ``rest + sum w * delta``; a change of weights rewrites only the rows the
    previous and the new active targets move, so a face shape animated on a large body costs
    its own few hundred rows per frame, not the body.

    Parameters
    ----------
    morphs : MorphTargets
    rest : (V, 3) float32
        The binding's rest points (read, never written).
    """

    def __init__(self, morphs, rest):
        if morphs.n_vertices != len(rest):
            raise ValueError(f"morph targets displace {morphs.n_vertices} vertices, the mesh "
                             f"has {len(rest)}")
        self.morphs = morphs
        self.rest = rest
        self.rest_normals = None
        self.weights = np.zeros(morphs.count)   # the weights in the buffers
        self.points, self.normals = rest, None  # what a skinning pass reads now
        self._buf = self._nbuf = None
        # the targets whose rows the buffers hold displaced: they go back to rest first
        self._dirty = set()
        # Each target's rows as an index into the buffers seen flat, (3V,): a slice when it
        # moves every vertex, else the 3n flat positions of its rows. The reset and
        # multiply-add of 30k rows measured 0.10 ms by slice, 3.2 ms by row index (an (n,)
        # index into a (V, 3) array); of 15k rows 0.4 ms by flat index, 1.5 ms by row index.
        v = len(rest)
        self._index = [slice(None) if len(r) == v else (3 * r[:, None] + np.arange(3)).ravel()
                       for r in (morphs.moved_rows(m) for m in range(morphs.count))]
        self._moves = np.array([len(morphs.moved_rows(m)) > 0 for m in range(morphs.count)],
                               dtype=bool)

    def bind_normals(self, rest_normals):
        """Use ``rest_normals`` (V, 3) float32 from now on (the weights re-applied)."""
        self.rest_normals = rest_normals
        self._nbuf = None
        weights, self.weights = self.weights, np.full(self.morphs.count, np.nan)
        self.set_weights(weights)

    def set_weights(self, weights):
        """Apply ``weights`` (anything :meth:`MorphTargets.weights_array` takes); returns
        True when the points changed."""
        mt = self.morphs
        w = mt.weights_array(weights)
        if np.array_equal(w, self.weights):
            return False
        self.weights = w
        active = np.flatnonzero((w != 0) & self._moves)
        if not len(active):
            self.points, self.normals = self.rest, self.rest_normals
            return True
        with_normals = self.rest_normals is not None and mt.normal_deltas is not None
        if self._buf is None:
            self._buf = self.rest.copy()
        if with_normals and self._nbuf is None:
            self._nbuf = self.rest_normals.copy()
            self._dirty = set(range(mt.count))   # a new normals buffer: all rows again
        # Back to rest: the rows of the targets displaced before and of those active now
        # (rows shared by two targets are reset twice, harmlessly), then each target's sum.
        # No union of rows is formed: np.unique over 30k rows took 7 ms.
        buf, rest = self._buf.reshape(-1), self.rest.reshape(-1)
        nbuf = self._nbuf.reshape(-1) if with_normals else None
        nrest = self.rest_normals.reshape(-1) if with_normals else None
        for m in self._dirty | set(active.tolist()):
            i = self._index[m]
            buf[i] = rest[i]
            if with_normals:
                nbuf[i] = nrest[i]
        for m in active:
            i = self._index[m]
            _, d, n = mt.sparse_target(m)
            # positions are unique within one target: the fancy-index add is exact
            buf[i] += np.float32(w[m]) * d.reshape(-1)
            if with_normals:
                nbuf[i] += np.float32(w[m]) * n.reshape(-1)
        self._dirty = set(active.tolist())
        self.points = self._buf
        self.normals = self._nbuf if with_normals else self.rest_normals
        return True
