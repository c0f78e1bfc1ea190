"""Bezier tracks in rigedit's clip JSON (:mod:`.clip_json`).

A bezier track's entry has no ``times``/``values`` of its own but three curves, X, Y, Z
(degrees of Euler angles in ``euler_order`` for a rotation, see
:mod:`rigedit.animation.euler_curves`)::

    {"joint": "Hips", "channel": "rotation", "interpolation": "bezier", "euler_order": "XYZ",
     "curves": [{"times": [0.0, 1.0], "values": [0.0, 90.0],
                 "interpolation": ["bezier", "bezier"],
                 "left": [[-0.33, 0.0], [0.67, 90.0]], "right": [[0.33, 0.0], [1.33, 90.0]],
                 "left_type": ["auto_clamped", "free"], "right_type": [...]}, {...}, {...}]}

Per key: its time, value, the interpolation of the segment it starts, both handles as
absolute ``[time, value]`` and their types. Handles of automatic types (auto, auto_clamped,
vector) are written but recomputed on reading, so a file edited by hand stays consistent.
"""
from __future__ import annotations

from ..animation.curve import HANDLE_TYPES, INTERPOLATIONS, Curve
from ..animation.euler_curves import EULER_ORDERS
from ..animation.track import Track
from ..errors import RigFileError
from .jsonfile import MAX_SECONDS, choice, numbers, optional, require

__all__ = ["bezier_entry", "read_bezier_track"]

#: Keys per curve a file may claim (a bound before anything is built from it).
MAX_CURVE_KEYS = 10_000_000


def bezier_entry(track):
    """The JSON fields of a bezier track (to merge into its entry)."""
    # full precision (Python's shortest round-tripping repr), not rounded as plain tracks
    # are: keys closer than the rounding would merge and the file would not load again, and
    # handles moved off the exact thirds of their segment would turn a CUBICSPLINE glTF
    # export of the loaded clip into a resampled one
    curves = [{"times": c.times.tolist(), "values": c.values.tolist(),
               "interpolation": list(c.interpolation), "left": c.left.tolist(),
               "right": c.right.tolist(), "left_type": list(c.left_type),
               "right_type": list(c.right_type)} for c in track.curves]
    out = {"interpolation": "bezier", "curves": curves}
    if track.channel == "rotation":
        out["euler_order"] = track.euler_order
    return out


def _names(path, value, what, allowed, count, where):
    if not isinstance(value, list) or len(value) != count:
        raise RigFileError(path, f"{where}: expected {what} to be a list of {count} names, got "
                                 f"{type(value).__name__}"
                                 + (f" of {len(value)}" if isinstance(value, list) else ""))
    return [choice(path, v, what, allowed, where=where) for v in value]


def _curve(path, data, where):
    if not isinstance(data, dict):
        raise RigFileError(path, f"{where}: expected an object, got {type(data).__name__}")
    times = numbers(path, require(path, data, "times", list, f" in {where}"), "'times'",
                    bound=MAX_SECONDS, where=where)
    n = len(times)
    if n == 0 or n > MAX_CURVE_KEYS:
        raise RigFileError(path, f"{where}: expected 1 to {MAX_CURVE_KEYS} keys, got {n}")
    if times.min() < 0:
        raise RigFileError(path, f"{where}: expected key times >= 0, got {times.min():g}")
    values = numbers(path, require(path, data, "values", list, f" in {where}"), "'values'",
                     count=n, where=where)
    fields = {}
    for key, allowed, default in (("interpolation", INTERPOLATIONS, "bezier"),
                                  ("left_type", HANDLE_TYPES, "auto_clamped"),
                                  ("right_type", HANDLE_TYPES, "auto_clamped")):
        fields[key] = _names(path, optional(data, key, [default] * n), f"'{key}'", allowed, n,
                             where)
    for key in ("left", "right"):
        value = optional(data, key, None)
        fields[key] = None if value is None else numbers(path, value, f"'{key}'", width=2,
                                                         count=n, where=where)
    try:
        return Curve(times, values, **fields)
    except ValueError as exc:
        raise RigFileError(path, f"{where}: {exc}") from None


def read_bezier_track(path, entry, channel, where):
    """The bezier Track of a clip JSON track entry; one RigFileError naming the file and the
    track for anything malformed."""
    curves = require(path, entry, "curves", list, f" in {where}")
    if len(curves) != 3:
        raise RigFileError(path, f"{where}: expected 3 curves (X, Y, Z), got {len(curves)}")
    order = "XYZ"
    if channel == "rotation":
        order = choice(path, optional(entry, "euler_order", "XYZ"), "'euler_order'",
                       EULER_ORDERS, where=where)
    built = [_curve(path, c, f"{where} curve {'XYZ'[a]}") for a, c in enumerate(curves)]
    return Track.from_curves(channel, built, order)
