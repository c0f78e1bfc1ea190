"""Clip JSON: rigedit's own format and the elk project's ``animations/NAME.json``.

rigedit format::

    {"format": "rigedit.clip", "version": 1, "name": "walk", "duration": 1.0, "loop": true,
     "tracks": [{"joint": "Hips", "channel": "rotation", "interpolation": "slerp",
                 "times": [0.0, 0.5, 1.0], "values": [[x, y, z, w], ...]}, ...]}

Values are local (parent-space) joint transforms, as in a Pose: translations, unit
quaternions (x, y, z, w), scales. A ``cubic_spline`` track (glTF's CUBICSPLINE) also has
``"tangents"``: per key, its in-tangent then its out-tangent (2 C numbers, units per second).

elk format: ``{"name", "duration", "keyframes": {joint: [{"time", "rotation": [rx, ry, rz],
"translation": [x, y, z], "scale": [x, y, z]}]}}`` with Euler radians composed Rz·Ry·Rx about
the joint's head in its axis-aligned frame, translation an offset from the rest position, and
linear interpolation.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ..animation.clip import CHANNELS, Clip, Track
from ..errors import RigFileError
from .atomic import write_json
from .jsonfile import read_json, require

__all__ = ["load_clip", "save_clip", "clip_to_dict", "UnknownJointsWarning"]


class UnknownJointsWarning(UserWarning):
    """A clip names joints that the skeleton lacks; their keys were skipped."""


def _floats(path, where, value, shape):
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.shape[1:] != shape[1:] or (shape[0] and arr.shape[0] != shape[0]) \
            or not np.all(np.isfinite(arr)):
        raise RigFileError(path, f"{where}: expected numbers of shape "
                                 f"{tuple('K' if s == 0 else s for s in shape)}, got {value!r:.80}")
    return arr


def _warn_unknown(path, unknown):
    if unknown:
        warnings.warn(f"{path}: skipped keys for joints the skeleton lacks: "
                      f"{', '.join(sorted(unknown))}", UnknownJointsWarning, stacklevel=3)


def _load_elk(path, data, skeleton):
    keyframes = require(path, data, "keyframes", dict)
    tracks, unknown = {}, []
    for joint, keys in keyframes.items():
        if joint not in skeleton.index:
            unknown.append(joint)
            continue
        if not isinstance(keys, list) or not keys:
            raise RigFileError(path, f"joint {joint!r}: expected a list of keyframes")
        j = skeleton.index[joint]
        times = _floats(path, f"joint {joint!r} times",
                        [require(path, k, "time", (int, float), f" in a key of {joint!r}")
                         for k in keys], (0,))
        euler = _floats(path, f"joint {joint!r} rotation",
                        [k.get("rotation", [0, 0, 0]) for k in keys], (0, 3))
        offset = _floats(path, f"joint {joint!r} translation",
                         [k.get("translation", [0, 0, 0]) for k in keys], (0, 3))
        scale = _floats(path, f"joint {joint!r} scale",
                        [k.get("scale", [1, 1, 1]) for k in keys], (0, 3))
        rest = Rotation.from_quat(skeleton.rest_rotation[j])
        quats = (rest * Rotation.from_euler("xyz", euler)).as_quat()
        try:
            tracks[(joint, "rotation")] = Track("rotation", times, quats, "nlerp")
            tracks[(joint, "translation")] = Track(
                "translation", times, skeleton.rest_translation[j] + offset, "linear")
            if np.any(scale != 1.0):
                tracks[(joint, "scale")] = Track("scale", times,
                                                 skeleton.rest_scale[j] * scale, "linear")
        except ValueError as exc:
            raise RigFileError(path, f"joint {joint!r}: {exc}") from None
    _warn_unknown(path, unknown)
    duration = data.get("duration")
    if duration is not None and not isinstance(duration, (int, float)):
        raise RigFileError(path, f"expected 'duration' to be a number, got {duration!r}")
    return tracks, duration, bool(data.get("loop", True))


def _load_rigedit(path, data, skeleton):
    entries = require(path, data, "tracks", list)
    tracks, unknown = {}, []
    for i, e in enumerate(entries):
        joint = require(path, e, "joint", str, f" in track {i}")
        channel = require(path, e, "channel", str, f" in track {i}")
        if channel not in CHANNELS:
            raise RigFileError(path, f"track {i} ({joint!r}): expected channel in "
                                     f"{sorted(CHANNELS)}, got {channel!r}")
        if joint not in skeleton.index:
            unknown.append(joint)
            continue
        times = _floats(path, f"track {i} ({joint!r} {channel}) times",
                        require(path, e, "times", list, f" in track {i}"), (0,))
        values = _floats(path, f"track {i} ({joint!r} {channel}) values",
                         require(path, e, "values", list, f" in track {i}"),
                         (len(times), CHANNELS[channel]))
        tangents = e.get("tangents")
        if tangents is not None:  # a cubic_spline track's in- and out-tangent per key
            tangents = _floats(path, f"track {i} ({joint!r} {channel}) tangents", tangents,
                               (len(times), 2 * CHANNELS[channel])).reshape(len(times), 2, -1)
        try:
            tracks[(joint, channel)] = Track(channel, times, values, e.get("interpolation"),
                                             tangents)
        except ValueError as exc:
            raise RigFileError(path, f"track {i} ({joint!r}): {exc}") from None
    _warn_unknown(path, set(unknown))
    return tracks, data.get("duration"), bool(data.get("loop", True))


def load_clip(path, skeleton):
    """Read a clip in either format and bind it to ``skeleton``.

    Keys for joints the skeleton lacks are skipped with one :class:`UnknownJointsWarning`
    naming them.

    Returns
    -------
    clip : Clip
    """
    path = Path(path)
    data = read_json(path)
    if not isinstance(data, dict):
        raise RigFileError(path, f"expected a JSON object, got {type(data).__name__}")
    if "keyframes" in data:
        tracks, duration, loop = _load_elk(path, data, skeleton)
    elif "tracks" in data:
        tracks, duration, loop = _load_rigedit(path, data, skeleton)
    else:
        raise RigFileError(path, "expected a clip with 'tracks' (rigedit) or 'keyframes' (elk), "
                                 "got neither")
    name = data.get("name") or path.stem
    try:
        return Clip(str(name), skeleton, tracks, duration, loop)
    except ValueError as exc:
        raise RigFileError(path, str(exc)) from None


def clip_to_dict(clip):
    """rigedit-format dictionary of a clip."""
    tracks = [{"joint": joint, "channel": channel, "interpolation": tr.interpolation,
               "times": tr.times.round(9).tolist(), "values": tr.values.round(9).tolist()}
              for (joint, channel), tr in clip.tracks.items()]
    for entry, tr in zip(tracks, clip.tracks.values()):
        if tr.interpolation == "cubic_spline":  # glTF's CUBICSPLINE keeps its own tangents
            entry["tangents"] = tr.tangents.reshape(len(tr), -1).round(9).tolist()
    return {"format": "rigedit.clip", "version": 1, "name": clip.name,
            "duration": clip.duration, "loop": clip.loop, "tracks": tracks}


def save_clip(path, clip):
    """Write a clip in rigedit's format, atomically."""
    write_json(path, clip_to_dict(clip))
