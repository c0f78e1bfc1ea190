"""Bezier curves of one scalar channel: keys with per-key interpolation and handles, as in
Blender's F-curves.

A :class:`Curve` holds K keys. Key ``k``'s interpolation names how the segment from key ``k``
to key ``k + 1`` is drawn (``constant``: hold, ``linear``, ``bezier``); the last key's is
unused. Every key has an in-handle (``left``) and an out-handle (``right``): absolute
``(time, value)`` points with a type each:

``auto``          smooth: the slope of the line through the two neighbours (Catmull-Rom-like),
                  each handle a third of its segment long in time
``auto_clamped``  as ``auto``, but flat at a key that is a local extreme and shortened so the
                  handles stay within the values of the keys either side: the segment then
                  never overshoots its keys (the default for new keys, as in Blender)
``aligned``       placed by the user; dragging one turns the other to stay collinear
``free``          placed by the user, independent
``vector``        pointing a third of the way to the neighbouring key
================  ==========================================================================

The end keys' automatic handles are flat (the curve holds its end values beyond the keys, as
Blender does with constant extrapolation). Handles' time extents are clamped so each segment
stays a function of time: a left handle is never after its key, a right one never before,
and when a segment's two handles together reach further than the segment is long both are
scaled down in proportion (Blender's ``BKE_fcurve_correct_bezpart``), so ``x(u)`` is monotone
and ``x(u) = t`` has one root, found by a few safeguarded Newton steps on all samples at once.

Curves are immutable: edits return new curves (automatic handles recomputed).
"""
from __future__ import annotations

import numpy as np

from .bezier import INTERPOLATIONS, bezier_points, evaluate, solve_u
from .curve_handles import ONE_KEY_HANDLE, place_handles, spans

__all__ = ["INTERPOLATIONS", "HANDLE_TYPES", "EASINGS", "AUTO_TYPES", "KEY_TOLERANCE", "Curve",
           "bezier_points", "solve_u", "evaluate", "ONE_KEY_HANDLE"]

HANDLE_TYPES = ("auto", "auto_clamped", "aligned", "free", "vector")
EASINGS = ("ease_in", "ease_out", "ease_in_out")
#: Types whose handles the curve places itself (recomputed after every edit).
AUTO_TYPES = ("auto", "auto_clamped", "vector")
#: Two key times closer than this (seconds) are the same key (tracks use the same).
KEY_TOLERANCE = 1e-6
#: Easing presets make the eased handle this fraction of its segment long (flat).
EASE_LENGTH = 0.6
#: What a handle type becomes when its handle must stay where it is (as a drag does).
_FROZEN = {"auto": "aligned", "auto_clamped": "aligned", "vector": "free"}


def _names(values, allowed, count, what, default):
    if values is None:
        return np.array([default] * count, dtype=object)
    if isinstance(values, str):
        values = [values] * count
    out = np.array(list(values), dtype=object)
    if out.shape != (count,):
        raise ValueError(f"curve: expected {count} {what} names, got {out.shape[0]}")
    bad = [v for v in out if v not in allowed]
    if bad:
        raise ValueError(f"curve: expected {what} in {allowed}, got {bad[0]!r}")
    return out


class Curve:
    """One scalar channel: K keys, per-key interpolation, Bezier handles (Blender's model).

    Parameters
    ----------
    times : (K,) float
        Seconds, strictly increasing.
    values : (K,) float
        Metres, scale factors, or degrees for Euler rotations.
    interpolation : (K,) str or str, optional
        From :data:`INTERPOLATIONS`; ``bezier`` when omitted.
    left, right : (K, 2) float, optional
        Absolute ``(time, value)`` of each key's in- and out-handle; computed for automatic
        types (and flat, a third of the segment, when omitted).
    left_type, right_type : (K,) str or str, optional
        From :data:`HANDLE_TYPES`; ``auto_clamped`` when omitted.
    """

    __slots__ = ("times", "values", "interpolation", "left", "right", "left_type",
                 "right_type", "_segments")

    def __init__(self, times, values, interpolation=None, left=None, right=None,
                 left_type=None, right_type=None):
        times = np.array(times, dtype=np.float64).reshape(-1)
        values = np.array(values, dtype=np.float64).reshape(-1)
        k = len(times)
        if k == 0:
            raise ValueError("curve: expected at least one key, got none")
        if values.shape != (k,):
            raise ValueError(f"curve: expected {k} values, got {values.shape[0]}")
        if not (np.all(np.isfinite(times)) and np.all(np.isfinite(values))):
            raise ValueError("curve: expected finite key times and values, got NaN or inf")
        if np.any(np.diff(times) <= 0):
            raise ValueError("curve: expected strictly increasing key times")
        self.times, self.values = times, values
        self.interpolation = _names(interpolation, INTERPOLATIONS, k, "interpolation",
                                    "bezier")
        self.left_type = _names(left_type, HANDLE_TYPES, k, "handle type", "auto_clamped")
        self.right_type = _names(right_type, HANDLE_TYPES, k, "handle type", "auto_clamped")
        flat_l, flat_r = self._flat_handles()
        self.left = self._points(left, flat_l, "left")
        self.right = self._points(right, flat_r, "right")
        self._place_handles()
        self._segments = None
        for a in ("times", "values", "left", "right"):
            getattr(self, a).flags.writeable = False

    # ------------------------------------------------------------------ handles
    def _spans(self):
        return spans(self.times)

    def _flat_handles(self):
        before, after = self._spans()
        return (np.stack([self.times - before / 3, self.values], axis=1),
                np.stack([self.times + after / 3, self.values], axis=1))

    def _points(self, given, default, side):
        if given is None:
            return default
        pts = np.array(given, dtype=np.float64)
        if pts.shape != default.shape:
            raise ValueError(f"curve: expected {side} handles of shape {default.shape}, got "
                             f"{pts.shape}")
        if not np.all(np.isfinite(pts)):
            raise ValueError(f"curve: expected finite {side} handles, got NaN or inf")
        # a function of time: the in-handle not after its key, the out-handle not before
        pts[:, 0] = np.minimum(pts[:, 0], self.times) if side == "left" else \
            np.maximum(pts[:, 0], self.times)
        return pts

    def _place_handles(self):
        """Recompute the automatic (auto, auto_clamped, vector) handles in place."""
        place_handles(self.times, self.values, self.left, self.right, self.left_type,
                      self.right_type)

    # ------------------------------------------------------------------ sampling
    def __len__(self):
        return len(self.times)

    def segments(self):
        """The control points of every segment, cached: ``(K - 1, 4, 2)`` per segment, key,
        out-handle, in-handle, key, with the handles' time extents corrected (see the module
        notes)."""
        if self._segments is None:
            codes = np.array([INTERPOLATIONS.index(n) for n in self.interpolation], np.int8)
            self._segments = (bezier_points(self.times, self.values, self.left, self.right),
                              codes)
        return self._segments[0]

    def codes(self):
        """(K,) int8 index of each key's interpolation in :data:`INTERPOLATIONS` (cached)."""
        self.segments()
        return self._segments[1]

    def sample(self, t):
        """Value(s) at time(s) ``t`` (scalar or (N,)), clamped to the first and last key."""
        scalar = np.ndim(t) == 0
        t = np.clip(np.asarray(t, dtype=np.float64).reshape(-1), self.times[0], self.times[-1])
        out = self._sample(t)
        return float(out[0]) if scalar else out

    def _sample(self, t):
        k = len(self.times)
        if k == 1:
            return np.full(len(t), self.values[0])
        i = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, k - 2)
        return evaluate(self.segments()[i], self.codes()[i], t)

    # ------------------------------------------------------------------ edits
    def _replace(self, **fields):
        names = ("times", "values", "interpolation", "left", "right", "left_type",
                 "right_type")
        args = {n: fields.get(n, getattr(self, n)) for n in names}
        return Curve(**args)

    def with_keys_moved(self, indices, dt, dv):
        """The keys ``indices`` moved by ``dt`` seconds and ``dv`` units, their handles with
        them (same offsets).

        A key is not passed over its neighbour: the move's time offset is clamped so every
        moved key stays more than :data:`MIN_GAP` from the unmoved keys (all moved keys by
        the same clamped offset, so their order and spacing are kept), and no key goes before
        time 0 (clips start there; their files refuse earlier keys).
        """
        idx = np.unique(np.asarray(indices, dtype=int).reshape(-1))
        if len(idx) == 0:
            return self
        dt = _clamp_shift(self.times, idx, float(dt))
        times, values = self.times.copy(), self.values.copy()
        left, right = self.left.copy(), self.right.copy()
        times[idx] += dt
        values[idx] += dv
        for pts in (left, right):
            pts[idx, 0] += dt
            pts[idx, 1] += dv
        return self._replace(times=times, values=values, left=left, right=right)

    def shift_range(self, indices):
        """``(low, high)``: the time offsets (seconds, low <= 0 <= high) by which
        :meth:`with_keys_moved` moves the keys ``indices`` unclamped. Keys selected on
        several curves move together by one offset clamped to every curve's range
        (:func:`rigedit.editor.graph_commands.moved_keys`), so keys of one time stay one."""
        idx = np.unique(np.asarray(indices, dtype=int).reshape(-1))
        if len(idx) == 0:
            return -np.inf, np.inf
        return _shift_bounds(self.times, idx)

    def with_handle(self, index, side, point):
        """Key ``index``'s ``side`` (``left``/``right``) handle at ``point`` (time, value).

        An auto or auto_clamped handle that is dragged becomes ``aligned`` (with the other side
        when that is auto too), a vector handle ``free``, as in Blender; an aligned handle's
        other side turns to stay collinear, keeping its length; a free handle moves alone.
        The time is clamped to the key's side.
        """
        if side not in ("left", "right"):
            raise ValueError(f"curve: expected side 'left' or 'right', got {side!r}")
        i = int(index)
        other = "right" if side == "left" else "left"
        lt, rt = self.left_type.copy(), self.right_type.copy()
        types = {"left": lt, "right": rt}
        if types[side][i] == "vector":       # Blender: a dragged vector handle is free
            types[side][i] = "free"
        elif types[side][i] in AUTO_TYPES:
            types[side][i] = "aligned"
            if types[other][i] in ("auto", "auto_clamped"):
                types[other][i] = "aligned"
        pts = {"left": self.left.copy(), "right": self.right.copy()}
        key = np.array([self.times[i], self.values[i]])
        p = np.array(point, dtype=np.float64).reshape(2)
        p[0] = min(p[0], key[0]) if side == "left" else max(p[0], key[0])
        pts[side][i] = p
        if types[side][i] == "aligned" and types[other][i] == "aligned":
            d = key - p
            n = np.hypot(*d)
            length = np.hypot(*(pts[other][i] - key))
            if n > 1e-12:
                pts[other][i] = key + d / n * length
        return self._replace(left=pts["left"], right=pts["right"], left_type=lt, right_type=rt)

    def with_key(self, t, value=None, tol=KEY_TOLERANCE, keep_shape=False):
        """A key inserted at ``t`` (``value``: the curve's value there when None; a key already
        within ``tol`` seconds of ``t`` takes the value instead). New keys are bezier,
        auto_clamped.

        ``keep_shape`` (the graph editor's Insert): the curve plays as before. A bezier
        segment is split where ``t`` falls on it (de Casteljau: the new key's handles
        aligned, the neighbours' handles on that side shortened along themselves), a linear
        or constant one gives the new key its interpolation, and the neighbouring keys'
        automatic handles are kept where they are (auto and auto_clamped become aligned,
        vector free, as a drag does), since recomputed against the new key they would bend
        the segments beside it by degrees. A ``value`` other than the curve's moves the new
        key (and its handles) to it.
        """
        t = float(t)
        v = self.sample(t) if value is None else float(value)
        near = np.flatnonzero(np.abs(self.times - t) <= tol)
        if len(near):
            return self.with_keys_moved(near, 0.0, v - self.values[near[0]])
        j = int(np.searchsorted(self.times, t))
        if keep_shape:
            return self._split(j, t, v)
        flat = np.array([t, v])

        def ins(a, x):
            return np.insert(a, j, x, axis=0)

        return Curve(ins(self.times, t), ins(self.values, v),
                     ins(self.interpolation, "bezier"), ins(self.left, flat),
                     ins(self.right, flat), ins(self.left_type, "auto_clamped"),
                     ins(self.right_type, "auto_clamped"))

    def _split(self, j, t, v):
        """:meth:`with_key` with ``keep_shape``: a key at ``t`` (index ``j`` once inserted)."""
        left, right = self.left.copy(), self.right.copy()
        lt, rt = self.left_type.copy(), self.right_type.copy()
        for i in (j - 1, j):
            if 0 <= i < len(self):
                for types in (lt, rt):
                    types[i] = _FROZEN.get(types[i], types[i])
        interp, new_l, new_r = "bezier", np.array([t, v]), np.array([t, v])
        kinds = ("auto_clamped", "auto_clamped")
        codes = self.interpolation.copy()
        # beyond the ends the curve holds its end value: a linear segment to the new key
        # holds it too (a bezier one would bend through the old end key's outer handle)
        if j == 0:
            interp = "linear"
        elif j == len(self):
            codes[-1] = "linear"
        else:
            k = j - 1
            interp = self.interpolation[k]
            if interp == "bezier":
                p = self.segments()[k]
                u = float(solve_u(p[None, :, 0], np.array([t]))[0])
                a, b, c = (p[:-1] + (p[1:] - p[:-1]) * u)     # de Casteljau, level 1
                d, e = a + (b - a) * u, b + (c - b) * u
                key = d + (e - d) * u
                shift = np.array([0.0, v - key[1]])
                right[k], left[k + 1] = a, c
                new_l, new_r = d + shift, e + shift
                kinds = ("aligned", "aligned")

        def ins(arr, x):
            return np.insert(arr, j, x, axis=0)

        return Curve(ins(self.times, t), ins(self.values, v), ins(codes, interp),
                     ins(left, new_l), ins(right, new_r), ins(lt, kinds[0]), ins(rt, kinds[1]))

    def without_keys(self, indices):
        """The curve without keys ``indices``; None when no key is left."""
        keep = np.ones(len(self.times), dtype=bool)
        keep[np.asarray(indices, dtype=int)] = False
        if not keep.any():
            return None
        return Curve(self.times[keep], self.values[keep], self.interpolation[keep],
                     self.left[keep], self.right[keep], self.left_type[keep],
                     self.right_type[keep])

    def with_interpolation(self, indices, name):
        """Keys ``indices``' segments (to the next key) drawn as ``name``."""
        interp = self.interpolation.copy()
        interp[np.asarray(indices, dtype=int)] = name
        return self._replace(interpolation=interp)

    def with_handle_type(self, indices, name, side="both"):
        """Handle type ``name`` on keys ``indices`` (``side``: left, right or both)."""
        idx = np.asarray(indices, dtype=int)
        lt, rt = self.left_type.copy(), self.right_type.copy()
        if side in ("left", "both"):
            lt[idx] = name
        if side in ("right", "both"):
            rt[idx] = name
        return self._replace(left_type=lt, right_type=rt)

    def with_easing(self, indices, name):
        """An easing preset on keys ``indices``: ``ease_in`` makes the in-handle flat and
        long (:data:`EASE_LENGTH` of its segment: the curve arrives slowly), ``ease_out``
        the out-handle, ``ease_in_out`` both. The eased handles become ``free`` (the other
        side keeps its type) and their segments bezier."""
        if name not in EASINGS:
            raise ValueError(f"curve: expected an easing in {EASINGS}, got {name!r}")
        idx = np.asarray(indices, dtype=int).reshape(-1)
        before, after = self._spans()
        left, right = self.left.copy(), self.right.copy()
        lt, rt = self.left_type.copy(), self.right_type.copy()
        interp = self.interpolation.copy()
        t, v = self.times[idx], self.values[idx]
        if name in ("ease_in", "ease_in_out"):
            left[idx] = np.stack([t - EASE_LENGTH * before[idx], v], axis=1)
            lt[idx] = "free"
            interp[np.maximum(idx - 1, 0)[idx > 0]] = "bezier"
        if name in ("ease_out", "ease_in_out"):
            right[idx] = np.stack([t + EASE_LENGTH * after[idx], v], axis=1)
            rt[idx] = "free"
            interp[idx] = "bezier"
        return self._replace(left=left, right=right, left_type=lt, right_type=rt,
                             interpolation=interp)

    def scaled(self, indices, time_pivot, time_factor, value_pivot, value_factor):
        """Keys ``indices`` (and their handles) scaled about ``(time_pivot, value_pivot)``.

        A time factor below :data:`MIN_TIME_FACTOR` (zero or negative: keys would merge or
        mirror in time, out of order) is raised to it; the scaled keys' times are then
        clamped between the unscaled neighbours as :meth:`with_keys_moved` does, and kept
        apart: keys squeezed against a neighbour (a large factor) or together (a small one)
        stay :data:`MIN_GAP` apart, or as far apart as they were or as the room between the
        neighbours allows when that is less (they never merge or swap).
        """
        if not np.isfinite(time_factor) or not np.isfinite(value_factor):
            raise ValueError(f"curve: expected finite factors, got {time_factor}, "
                             f"{value_factor}")
        time_factor = max(float(time_factor), MIN_TIME_FACTOR)
        idx = np.unique(np.asarray(indices, dtype=int).reshape(-1))
        times, values = self.times.copy(), self.values.copy()
        left, right = self.left.copy(), self.right.copy()
        # written as x + (x - pivot) (factor - 1), not pivot + (x - pivot) factor: a factor
        # of 1 (a scale confirmed without moving the mouse) then leaves every time bitwise
        # where it was, instead of an ulp off (a key an ulp from the same key of the track's
        # other axes, and an undo step for nothing)
        t_grow, v_grow = time_factor - 1.0, float(value_factor) - 1.0
        t = times[idx]
        new_t = _spaced(self.times, idx, t + (t - time_pivot) * t_grow)
        for pts in (left, right):
            pts[idx, 0] += (new_t - t) + (pts[idx, 0] - t) * t_grow
            pts[idx, 1] += (pts[idx, 1] - value_pivot) * v_grow
        times[idx] = new_t
        values[idx] += (values[idx] - value_pivot) * v_grow
        return self._replace(times=times, values=values, left=left, right=right)

    def key_near(self, t, v, t_tol, v_tol):
        """Index of the key nearest ``(t, v)`` within ``t_tol`` seconds and ``v_tol`` units
        (distance measured in tolerances), or None."""
        d = np.hypot((self.times - t) / t_tol, (self.values - v) / v_tol)
        i = int(np.argmin(d))
        return i if d[i] <= 1.0 else None

    def __eq__(self, other):
        if not isinstance(other, Curve) or len(other) != len(self):
            return NotImplemented if not isinstance(other, Curve) else False
        return (all(np.array_equal(getattr(self, a), getattr(other, a))
                    for a in ("times", "values", "left", "right"))
                and all(list(getattr(self, a)) == list(getattr(other, a))
                        for a in ("interpolation", "left_type", "right_type")))

    __hash__ = None

    def __repr__(self):
        return (f"Curve({len(self)} keys, {self.times[0]:g}..{self.times[-1]:g}s, "
                f"{', '.join(sorted(set(self.interpolation)))})")


#: Closest two keys may come (seconds) when a key is moved towards its neighbour.
MIN_GAP = 1e-4
#: Smallest time factor of :meth:`Curve.scaled` (keys are not mirrored in time).
MIN_TIME_FACTOR = 1e-3


def _bounds(times, idx):
    """(M,) times of the nearest unmoved key before and after each moved key (+-inf)."""
    moved = np.zeros(len(times), dtype=bool)
    moved[idx] = True
    fixed = np.flatnonzero(~moved)
    if len(fixed) == 0:
        return np.full(len(idx), -np.inf), np.full(len(idx), np.inf)
    pos = np.searchsorted(fixed, idx)
    lo = np.where(pos > 0, times[fixed[np.maximum(pos - 1, 0)]], -np.inf)
    hi = np.where(pos < len(fixed), times[fixed[np.minimum(pos, len(fixed) - 1)]], np.inf)
    return lo, hi


def _gaps(times, idx):
    """(M,) least distance each moved key keeps from its unmoved neighbours: :data:`MIN_GAP`,
    or less where the key is already closer (a file may hold keys 1e-9 s apart; a move
    never pushes them apart nor brings them closer)."""
    lo, hi = _bounds(times, idx)
    t = times[idx]
    return lo, hi, np.minimum(MIN_GAP, t - lo), np.minimum(MIN_GAP, hi - t)


def _clamp_shift(times, idx, dt):
    """``dt`` clamped so the keys ``idx`` shifted by it stay between their unmoved
    neighbours (:func:`_gaps` apart) and not before time 0 (a clip's start; a key already
    before it does not move further back). The range always holds 0."""
    return float(np.clip(dt, *_shift_bounds(times, idx)))


def _shift_bounds(times, idx):
    """(low, high) of :func:`_clamp_shift`'s range for the sorted keys ``idx``."""
    lo, hi, gap_lo, gap_hi = _gaps(times, idx)
    t = times[idx]
    floor = np.maximum(lo + gap_lo, np.minimum(t, 0.0))   # clips start at 0
    low, high = np.max(floor - t), np.min(hi - gap_hi - t)
    return min(float(low), 0.0), max(float(high), 0.0)


def _spaced(times, idx, wanted):
    """(M,) the times ``wanted`` for the sorted keys ``idx``, clamped between their unmoved
    neighbours and not before time 0 (as :func:`_clamp_shift`), and strictly increasing: each
    run of moved keys between the same two unmoved ones keeps its keys a gap apart, the
    least of :data:`MIN_GAP`, the run's closest keys now, and an even share of the room."""
    lo, hi, gap_lo, gap_hi = _gaps(times, idx)
    out = np.asarray(wanted, dtype=np.float64).copy()
    t = times[idx]
    runs = np.flatnonzero(np.r_[True, (lo[1:] != lo[:-1]) | (hi[1:] != hi[:-1])])
    for start, stop in zip(runs, np.r_[runs[1:], len(idx)]):
        a, b = float(lo[start]), float(hi[start])
        floor = max(a + gap_lo[start], min(float(t[start]), 0.0))
        ceil = b - gap_hi[stop - 1]
        m = stop - start
        gap = min(MIN_GAP, float(np.min(np.diff(t[start:stop]), initial=np.inf)),
                  (ceil - floor) / max(m - 1, 1) if np.isfinite(ceil) else np.inf)
        run = np.clip(out[start:stop], floor, ceil)
        if np.any(np.diff(run) < gap):   # (else untouched: no rounding of spaced keys)
            steps = gap * np.arange(m)
            # forward: at least a gap after the key before; backward: a gap before the next
            run = np.minimum(np.maximum.accumulate(run - steps) + steps, ceil)
            run = np.minimum.accumulate((run - steps)[::-1])[::-1] + steps
        out[start:stop] = run
    return out
