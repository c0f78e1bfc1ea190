"""Tracks: the keys of one channel (translation, rotation or scale) of one joint."""
from __future__ import annotations

import numpy as np

from .curve import KEY_TOLERANCE, Curve
from .curve_track import curves_from_track, remove_times, retime
from .euler_curves import DEFAULT_ORDER, EULER_ORDERS, euler_to_quat, quat_to_euler
from .interpolate import (ROTATION_MODES, VECTOR_MODES, catmull_rom_tangents, sample_many,
                          sample_track)

__all__ = ["CHANNELS", "DEFAULT_MODE", "KEY_TOLERANCE", "Track", "curves_from_track"]

#: Channel name -> value width.
CHANNELS = {"translation": 3, "rotation": 4, "scale": 3}
DEFAULT_MODE = {"translation": "linear", "rotation": "slerp", "scale": "linear"}


class Track:
    """Keys of one channel of one joint.

    Parameters
    ----------
    channel : {"translation", "rotation", "scale"}
    times : (K,) float
        Key times in seconds, strictly increasing after sorting (duplicates rejected).
    values : (K, C) float
        Local values: translations and scales (C = 3) or quaternions x, y, z, w (C = 4).
    interpolation : str
        ``step``, ``linear`` or ``catmull_rom`` for vectors; ``step``, ``nlerp``, ``slerp``,
        ``hybrid`` or ``catmull_rom`` for rotations (``linear`` on a rotation is read as
        ``nlerp``); ``cubic_spline`` for all three. See :mod:`rigedit.animation.interpolate`.
        A ``bezier`` track is made with :meth:`from_curves` instead.
    tangents : (K, 2, C) float, optional
        ``cubic_spline`` only: the in- and out-tangent of each key (units per second, glTF's
        CUBICSPLINE); the Catmull-Rom tangents when omitted.

    Notes
    -----
    Keys are validated once here: sorted by time, quaternions normalised and each flipped to
    its predecessor's hemisphere so that every interpolation takes the shortest path without a
    per-frame test. Tracks are treated as immutable: edits return new tracks, so an undo
    snapshot of a clip is a shallow copy of its track dictionary.

    A ``bezier`` track (:meth:`from_curves`) holds three :class:`~rigedit.animation.curve.Curve`
    (``curves``: X, Y, Z of the translation or scale, or Euler angles in degrees for a
    rotation, in ``euler_order``); its ``times`` are the union of the curves' key times and its
    ``values`` the channel sampled there, so code that reads keys keeps working. Key edits
    (:meth:`with_key`, :meth:`without_keys`, :meth:`with_moved_keys`) edit the curves;
    :meth:`with_interpolation` with another mode converts it back to a plain track keyed at
    ``times`` (the in-between shape of the curves is then that mode's).
    """

    __slots__ = ("channel", "times", "values", "interpolation", "tangents", "curves",
                 "euler_order")

    def __init__(self, channel, times, values, interpolation=None, tangents=None):
        if channel not in CHANNELS:
            raise ValueError(f"expected a channel in {sorted(CHANNELS)}, got {channel!r}")
        if interpolation == "bezier":
            raise ValueError(f"{channel} track: a bezier track is made from curves "
                             f"(Track.from_curves)")
        self.channel = channel
        self.curves = self.euler_order = None
        width = CHANNELS[channel]
        times = np.asarray(times, dtype=np.float64).reshape(-1)
        values = np.asarray(values, dtype=np.float64)
        if len(times) == 0:
            raise ValueError(f"{channel} track: expected at least one key, got none")
        if values.shape != (len(times), width):
            raise ValueError(f"{channel} track: expected values of shape {(len(times), width)}, "
                             f"got {values.shape}")
        if not (np.all(np.isfinite(times)) and np.all(np.isfinite(values))):
            raise ValueError(f"{channel} track: expected finite numbers, got NaN or inf")
        order = np.argsort(times, kind="stable")
        times, values = times[order], values[order]
        if np.any(np.diff(times) <= 0):
            dup = times[1:][np.diff(times) <= 0][0]
            raise ValueError(f"{channel} track: two keys at time {dup:g}")
        mode = interpolation or DEFAULT_MODE[channel]
        if channel == "rotation" and mode == "linear":
            mode = "nlerp"
        allowed = ROTATION_MODES if channel == "rotation" else VECTOR_MODES
        if mode not in allowed:
            raise ValueError(f"{channel} track: expected interpolation in {allowed}, got {mode!r}")
        if channel == "rotation":
            norm = np.linalg.norm(values, axis=1, keepdims=True)
            if np.any(norm < 1e-12):
                raise ValueError("rotation track: expected unit quaternions, got a zero one")
            if mode == "cubic_spline" and tangents is not None:
                # the spline runs through the keys as given with their tangents (glTF
                # evaluates it on the raw quaternions, then normalises): flipping or scaling a
                # key would change the curve
                pass
            else:
                values = _hemisphere_aligned(values / norm)
        self.times, self.values, self.interpolation = times, values, mode
        # baked once: per-frame sampling of a spline is then one cubic
        self.tangents = None
        if mode == "catmull_rom":
            self.tangents = catmull_rom_tangents(times, values)
        elif mode == "cubic_spline":
            if tangents is None:
                tangents = np.repeat(catmull_rom_tangents(times, values)[:, None], 2, axis=1)
            tangents = np.asarray(tangents, dtype=np.float64)
            if tangents.shape != (len(times), 2, width):
                raise ValueError(f"{channel} track: expected tangents of shape "
                                 f"{(len(times), 2, width)}, got {tangents.shape}")
            if not np.all(np.isfinite(tangents)):
                raise ValueError(f"{channel} track: expected finite tangents, got NaN or inf")
            self.tangents = tangents[order]

    @classmethod
    def from_curves(cls, channel, curves, euler_order=DEFAULT_ORDER):
        """A ``bezier`` track of three curves (X, Y, Z; degrees in ``euler_order`` for a
        rotation, see :mod:`rigedit.animation.euler_curves`)."""
        if channel not in CHANNELS:
            raise ValueError(f"expected a channel in {sorted(CHANNELS)}, got {channel!r}")
        curves = tuple(curves)
        if len(curves) != 3 or not all(isinstance(c, Curve) for c in curves):
            raise ValueError(f"{channel} track: expected 3 curves (X, Y, Z), got {len(curves)}")
        rotation = channel == "rotation"
        if rotation and euler_order not in EULER_ORDERS:
            raise ValueError(f"rotation track: expected an Euler order in {EULER_ORDERS}, "
                             f"got {euler_order!r}")
        self = object.__new__(cls)
        self.channel, self.curves, self.interpolation, self.tangents = (
            channel, curves, "bezier", None)
        self.euler_order = euler_order if rotation else None
        self.times = np.unique(np.concatenate([c.times for c in curves]))
        self.values = self.curve_values(self.times)
        return self

    def curve_values(self, times):
        """(N, C) values of a bezier track at ``times`` (each within the curves' keys)."""
        v = np.stack([c.sample(np.asarray(times, dtype=float)) for c in self.curves], axis=1)
        if self.channel != "rotation":
            return v
        return _hemisphere_aligned(euler_to_quat(v, self.euler_order))

    def _with_curves(self, curves):
        return Track.from_curves(self.channel, curves, self.euler_order or DEFAULT_ORDER)

    def _spline_tangents(self, keep):
        """In/out tangents of the kept keys (a boolean mask or index array) for a rebuilt
        ``cubic_spline`` track; None for other modes."""
        return self.tangents[keep] if self.interpolation == "cubic_spline" else None

    def _with(self, times, values, tangents):
        """A new track of the same channel and mode; ``tangents`` rows that are NaN (new keys
        of a ``cubic_spline`` track) get the Catmull-Rom tangent there."""
        if tangents is not None and np.isnan(tangents).any():
            order = np.argsort(times, kind="stable")
            cr = np.empty_like(tangents)
            cr[order] = catmull_rom_tangents(np.asarray(times)[order],
                                             np.asarray(values)[order])[:, None]
            tangents = np.where(np.isnan(tangents), cr, tangents)
        return Track(self.channel, times, values, self.interpolation, tangents)

    def __len__(self):
        return len(self.times)

    def sample(self, t):
        """(C,) value at time ``t`` (clamped to the first and last key)."""
        if self.curves is not None:
            return self.curve_values(np.array([float(t)]))[0]
        return sample_track(self.times, self.values, t, self.interpolation,
                            self.channel == "rotation", self.tangents)

    def sample_many(self, ts):
        """(N, C) values at times ``ts`` (N,), each clamped to the first and last key: one
        vectorised call (:func:`~rigedit.animation.interpolate.sample_many`)."""
        if self.curves is not None:
            return self.curve_values(np.clip(ts, self.times[0], self.times[-1]))
        return sample_many(self.times, self.values, ts, self.interpolation,
                           self.channel == "rotation", self.tangents)

    def key_index(self, t, tol=KEY_TOLERANCE):
        """Index of the key within ``tol`` seconds of ``t``, or None."""
        i = int(np.argmin(np.abs(self.times - t)))
        return i if abs(self.times[i] - t) <= tol else None

    def with_key(self, t, value):
        """A new track with a key set at ``t`` (replacing one at the same time)."""
        if self.curves is not None:
            value = np.asarray(value, dtype=float)
            if self.channel == "rotation":   # the Euler triple nearest the curves' there
                near = [c.sample(t) for c in self.curves]
                value = quat_to_euler(value[None], self.euler_order, near)[0]
            return self._with_curves(c.with_key(t, value[a]) for a, c in enumerate(self.curves))
        keep = np.abs(self.times - t) > KEY_TOLERANCE
        tangents = self._spline_tangents(keep)
        if tangents is not None:
            tangents = np.concatenate([tangents, np.full((1,) + tangents.shape[1:], np.nan)])
        return self._with(np.r_[self.times[keep], t],
                          np.vstack([self.values[keep], np.asarray(value, dtype=float)]),
                          tangents)

    def without_keys(self, times, tol=KEY_TOLERANCE):
        """A new track without the keys at ``times``; None when no key would remain."""
        times = np.atleast_1d(np.asarray(times, dtype=float))
        if self.curves is not None:
            curves = remove_times(self.curves, times, tol)
            return None if curves is None else self._with_curves(curves)
        keep = np.all(np.abs(self.times[:, None] - times[None, :]) > tol, axis=1)
        if not keep.any():
            return None
        return self._with(self.times[keep], self.values[keep], self._spline_tangents(keep))

    def with_moved_keys(self, mapping, tol=KEY_TOLERANCE):
        """A new track with keys moved: ``mapping`` is ``{old time: new time}``.

        A moved key replaces a key already at its new time (one that is not moving itself).
        """
        if self.curves is not None:
            curves = [retime(c, mapping, tol) for c in self.curves]
            if all(a is b for a, b in zip(curves, self.curves)):
                return self
            return self._with_curves(curves)
        new_t, new_v = [], []
        moved = set()
        for old, new in mapping.items():
            i = self.key_index(old, tol)
            if i is not None:
                moved.add(i)
                new_t.append(float(new))
                new_v.append(self.values[i])
        if not moved:
            return self
        rest = [i for i in range(len(self.times)) if i not in moved
                and np.all(np.abs(self.times[i] - np.asarray(new_t)) > tol)]
        times = np.r_[self.times[rest], new_t]
        values = np.vstack([self.values[rest].reshape(-1, self.values.shape[1]), new_v])
        tangents = None
        if self.interpolation == "cubic_spline":
            src = [self.key_index(old, tol) for old in mapping]
            tangents = np.concatenate([self.tangents[rest],
                                       self.tangents[[i for i in src if i is not None]]])
        return self._with(times, values, tangents)

    def with_interpolation(self, mode):
        """The same keys with another interpolation mode: ``bezier`` converts the track to
        curves (:func:`~rigedit.animation.curve_track.curves_from_track`); another mode on a
        bezier track keeps the keys at :attr:`times` with their values."""
        if mode == "bezier":
            if self.curves is not None:
                return self
            return Track.from_curves(self.channel, curves_from_track(self))
        return Track(self.channel, self.times, self.values, mode)

    def copy(self):
        if self.curves is not None:   # curves are immutable
            return self._with_curves(self.curves)
        return Track(self.channel, self.times.copy(), self.values.copy(), self.interpolation,
                     self._spline_tangents(slice(None)))


def _hemisphere_aligned(values):
    """(K, 4) unit quaternions, each flipped to its predecessor's hemisphere."""
    # key i flips when an odd number of the raw neighbour products up to i are negative (the
    # same as a loop, without one)
    values = np.array(values, dtype=np.float64)
    dots = np.sum(values[1:] * values[:-1], axis=1)
    flips = np.cumprod(np.where(dots < 0, -1.0, 1.0))
    values[1:] *= flips[:, None]
    return values
