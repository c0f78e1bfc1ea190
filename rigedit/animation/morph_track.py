"""Weight tracks: one morph target's weight over time (glTF ``weights`` channels, FBX shape
channels).

The interpolation names are glTF's (``LINEAR``, ``STEP``, ``CUBICSPLINE``) because that is
where weight tracks come from and go to; a CUBICSPLINE track keeps the file's in- and
out-tangent of every key (weight per second), evaluated as glTF's cubic Hermite.
"""
from __future__ import annotations

import numpy as np

from .interpolate import catmull_rom_tangents, hermite, segment
from .track import KEY_TOLERANCE

__all__ = ["WEIGHT_MODES", "WeightTrack"]

WEIGHT_MODES = ("LINEAR", "STEP", "CUBICSPLINE")


class WeightTrack:
    """Keys of one morph target's weight.

    Parameters
    ----------
    times : (K,) float
        Key times in seconds; sorted here, duplicates and non-finite numbers rejected.
    values : (K,) float
        Weights (any finite number: glTF does not bound them to [0, 1]).
    interpolation : {"LINEAR", "STEP", "CUBICSPLINE"}
        Lower case is accepted.
    in_tangents, out_tangents : (K,) float, optional
        CUBICSPLINE only: per key, weight per second; the Catmull-Rom tangents when omitted.

    Notes
    -----
    Immutable like :class:`rigedit.animation.clip.Track`: edits return new tracks, so an undo
    snapshot of a clip is a shallow copy of its dictionaries.
    """

    __slots__ = ("times", "values", "interpolation", "in_tangents", "out_tangents")

    def __init__(self, times, values, interpolation="LINEAR", in_tangents=None,
                 out_tangents=None):
        times = np.asarray(times, dtype=np.float64).reshape(-1)
        values = np.asarray(values, dtype=np.float64).reshape(-1)
        if len(times) == 0:
            raise ValueError("weight track: expected at least one key, got none")
        if values.shape != times.shape:
            raise ValueError(f"weight track: expected {len(times)} values, got {len(values)}")
        if not (np.isfinite(times).all() and np.isfinite(values).all()):
            raise ValueError("weight track: expected finite numbers, got NaN or inf")
        mode = str(interpolation).upper()
        if mode not in WEIGHT_MODES:
            raise ValueError(f"weight track: expected interpolation in {WEIGHT_MODES}, "
                             f"got {interpolation!r}")
        order = np.argsort(times, kind="stable")
        times, values = times[order], values[order]
        if np.any(np.diff(times) <= 0):
            dup = times[1:][np.diff(times) <= 0][0]
            raise ValueError(f"weight track: two keys at time {dup:g}")
        self.times, self.values, self.interpolation = times, values, mode
        self.in_tangents = self.out_tangents = None
        if mode == "CUBICSPLINE":
            default = catmull_rom_tangents(times, values[:, None])[:, 0]
            self.in_tangents = self._tangent(in_tangents, order, default, "in")
            self.out_tangents = self._tangent(out_tangents, order, default, "out")

    @staticmethod
    def _tangent(given, order, default, which):
        """(K,) tangents from ``given`` (None -> ``default``; NaN entries -> ``default``)."""
        if given is None:
            return default
        given = np.asarray(given, dtype=np.float64).reshape(-1)
        if given.shape != default.shape:
            raise ValueError(f"weight track: expected {len(default)} {which}-tangents, "
                             f"got {len(given)}")
        given = given[order]
        if np.isinf(given).any():
            raise ValueError(f"weight track: expected finite {which}-tangents, got inf")
        return np.where(np.isnan(given), default, given)

    def __len__(self):
        return len(self.times)

    def sample(self, t) -> float:
        """The weight at time ``t`` (clamped to the first and last key)."""
        i, k, u = segment(self.times, t)
        if i == k or self.interpolation == "STEP":
            return float(self.values[i])
        v0, v1 = self.values[i], self.values[k]
        if self.interpolation == "CUBICSPLINE":
            return float(hermite(v0, v1, self.out_tangents[i], self.in_tangents[k],
                                 self.times[k] - self.times[i], u))
        return float(v0 + (v1 - v0) * u)

    def key_index(self, t, tol=KEY_TOLERANCE):
        """Index of the key within ``tol`` seconds of ``t``, or None."""
        i = int(np.argmin(np.abs(self.times - t)))
        return i if abs(self.times[i] - t) <= tol else None

    def _with(self, times, values, keep=None, new=0):
        """A track of the same mode over ``times``/``values``: the kept keys keep their
        tangents, ``new`` appended keys get the Catmull-Rom ones."""
        if self.interpolation != "CUBICSPLINE":
            return WeightTrack(times, values, self.interpolation)
        pad = np.full(new, np.nan)
        return WeightTrack(times, values, "CUBICSPLINE",
                           np.r_[self.in_tangents[keep], pad], np.r_[self.out_tangents[keep], pad])

    def with_key(self, t, value):
        """A new track with a key ``value`` at ``t`` (replacing one at the same time)."""
        keep = np.abs(self.times - t) > KEY_TOLERANCE
        return self._with(np.r_[self.times[keep], float(t)],
                          np.r_[self.values[keep], float(value)], keep, 1)

    def without_keys(self, times, tol=KEY_TOLERANCE):
        """A new track without the keys at ``times``; None when no key would remain."""
        times = np.atleast_1d(np.asarray(times, dtype=float))
        keep = np.all(np.abs(self.times[:, None] - times[None, :]) > tol, axis=1)
        if not keep.any():
            return None
        return self._with(self.times[keep], self.values[keep], keep)

    def with_moved_keys(self, mapping, tol=KEY_TOLERANCE):
        """A new track with keys moved (``{old time: new time}``); a moved key replaces a
        resting key at its new time. ``self`` when no key moves."""
        src, dst = [], []
        for old, new in mapping.items():
            i = self.key_index(old, tol)
            if i is not None:
                src.append(i)
                dst.append(float(new))
        if not src:
            return self
        rest = [i for i in range(len(self.times)) if i not in src
                and np.all(np.abs(self.times[i] - np.asarray(dst)) > tol)]
        idx = np.r_[rest, src].astype(np.int64)
        return self._with(np.r_[self.times[rest], dst], self.values[idx], idx)

    def copy(self):
        return WeightTrack(self.times.copy(), self.values.copy(), self.interpolation,
                           self.in_tangents, self.out_tangents)

    def __repr__(self):
        return f"WeightTrack({len(self)} keys, {self.interpolation})"
