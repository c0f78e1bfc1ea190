"""Clip JSON: rigedit's own format and the elk project's ``animations/NAME.json``.

rigedit format::

    {"format": "rigedit.clip", "version": 1, "name": "walk", "duration": 1.0, "loop": true,
     "tracks": [{"joint": "Hips", "channel": "rotation", "interpolation": "slerp",
                 "times": [0.0, 0.5, 1.0], "values": [[x, y, z, w], ...]}, ...]}

Values are local (parent-space) joint transforms, as in a Pose: translations, unit
quaternions (x, y, z, w), scales. A ``cubic_spline`` track (glTF's CUBICSPLINE) also has
``"tangents"``: per key, its in-tangent then its out-tangent (2 C numbers, units per second).
A ``bezier`` track has three ``"curves"`` instead of times and values
(:mod:`.clip_json_bezier`).

Morph target weights (optional, absent in older files)::

    "morph_tracks": [{"target": "smile", "interpolation": "LINEAR",
                      "times": [0.0, 1.0], "values": [0.0, 1.0]}, ...]

one per target, interpolation ``LINEAR``, ``STEP`` or ``CUBICSPLINE`` (glTF's names; a
CUBICSPLINE track also has ``"in_tangents"`` and ``"out_tangents"``, one number per key,
weight per second). Targets are names only: the clip does not know the mesh, and a rig
ignores the weights of targets it lacks.

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
from ..animation.morph_track import WEIGHT_MODES, WeightTrack
from ..errors import RigFileError
from .atomic import write_json
from .clip_json_bezier import bezier_entry, read_bezier_track
from .jsonfile import (MAX_SECONDS, boolean, choice, name, number, numbers, optional,
                       read_json, require, vector)

__all__ = ["load_clip", "save_clip", "clip_to_dict", "UnknownJointsWarning"]


class UnknownJointsWarning(UserWarning):
    """A clip names joints that the skeleton lacks; their keys were skipped."""


def _warn_unknown(path, unknown):
    if unknown:
        warnings.warn(f"{path}: skipped keys for joints the skeleton lacks: "
                      f"{', '.join(sorted(unknown))}", UnknownJointsWarning, stacklevel=3)


def _duration(path, data):
    value = optional(data, "duration", None)
    return None if value is None else number(path, value, "'duration'", 0.0, MAX_SECONDS)


def _loop(path, data):
    return boolean(path, optional(data, "loop", True), "'loop'")


def _load_elk(path, data, skeleton):
    keyframes = require(path, data, "keyframes", dict)
    tracks, unknown = {}, []
    for joint, keys in keyframes.items():
        if joint not in skeleton.index:
            unknown.append(joint)
            continue
        if not isinstance(keys, list) or not keys:
            raise RigFileError(path, f"joint {joint!r}: expected a list of keyframes, got "
                                     f"{type(keys).__name__}")
        j = skeleton.index[joint]
        times, euler, offset, scale = [], [], [], []
        for i, k in enumerate(keys):
            where = f"joint {joint!r} key {i}"
            times.append(number(path, require(path, k, "time", (int, float), f" in {where}"),
                                "'time'", -MAX_SECONDS, MAX_SECONDS, where=where))
            euler.append(vector(path, optional(k, "rotation", [0, 0, 0]), 3, "'rotation'",
                                where=where))
            offset.append(vector(path, optional(k, "translation", [0, 0, 0]), 3,
                                 "'translation'", where=where))
            scale.append(vector(path, optional(k, "scale", [1, 1, 1]), 3, "'scale'",
                                where=where))
        euler, offset, scale = np.array(euler), np.array(offset), np.array(scale)
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
    return tracks, _duration(path, data), _loop(path, data)


def _load_rigedit(path, data, skeleton):
    entries = require(path, data, "tracks", list)
    tracks, unknown = {}, []
    for i, e in enumerate(entries):
        joint = name(path, require(path, e, "joint", str, f" in track {i}"), "'joint'",
                     where=f"track {i}")
        channel = choice(path, require(path, e, "channel", str, f" in track {i}"), "'channel'",
                         tuple(CHANNELS), where=f"track {i} ({joint!r})")
        if joint not in skeleton.index:
            unknown.append(joint)
            continue
        where = f"track {i} ({joint!r} {channel})"
        if optional(e, "interpolation", None) == "bezier":
            tracks[(joint, channel)] = read_bezier_track(path, e, channel, where)
            continue
        times = numbers(path, require(path, e, "times", list, f" in track {i}"),
                        "'times'", bound=MAX_SECONDS, where=where)
        if len(times) and times.min() < 0:   # a clip starts at 0 (as morph tracks do)
            raise RigFileError(path, f"{where}: expected key times >= 0, got {times.min():g}")
        values = numbers(path, require(path, e, "values", list, f" in track {i}"),
                         "'values'", width=CHANNELS[channel], count=len(times), where=where)
        mode = optional(e, "interpolation", None)
        if mode is not None and not isinstance(mode, str):
            raise RigFileError(path, f"{where}: expected 'interpolation' to be a name, got "
                                     f"{type(mode).__name__}")
        tangents = optional(e, "tangents", None)
        if tangents is not None:  # a cubic_spline track's in- and out-tangent per key
            tangents = numbers(path, tangents, "'tangents'", width=2 * CHANNELS[channel],
                               count=len(times), where=where).reshape(len(times), 2, -1)
        try:
            tracks[(joint, channel)] = Track(channel, times, values, mode, tangents)
        except ValueError as exc:
            raise RigFileError(path, f"track {i} ({joint!r}): {exc}") from None
    _warn_unknown(path, set(unknown))
    return tracks, _duration(path, data), _loop(path, data)


def _load_morph_tracks(path, data):
    """``{target: WeightTrack}`` of a rigedit clip's ``"morph_tracks"`` (empty without)."""
    entries = optional(data, "morph_tracks", [])
    if not isinstance(entries, list):
        raise RigFileError(path, f"expected 'morph_tracks' to be a list, got "
                                 f"{type(entries).__name__}")
    tracks = {}
    for i, e in enumerate(entries):
        target = name(path, require(path, e, "target", str, f" in morph track {i}"),
                      "'target'", where=f"morph track {i}")
        where = f"morph track {i} ({target!r})"
        if target in tracks:
            raise RigFileError(path, f"{where}: a second track for the same target")
        mode = choice(path, optional(e, "interpolation", "LINEAR"), "'interpolation'",
                      WEIGHT_MODES, where=where)
        times = numbers(path, require(path, e, "times", list, f" in {where}"), "'times'",
                        bound=MAX_SECONDS, where=where)
        if len(times) and times.min() < 0:
            raise RigFileError(path, f"{where}: expected key times >= 0, got {times.min():g}")
        values = numbers(path, require(path, e, "values", list, f" in {where}"), "'values'",
                         count=len(times), where=where)
        tangents = [None if optional(e, key, None) is None else
                    numbers(path, e[key], repr(key), count=len(times), where=where)
                    for key in ("in_tangents", "out_tangents")]
        try:
            tracks[target] = WeightTrack(times, values, mode, *tangents)
        except ValueError as exc:
            raise RigFileError(path, f"{where}: {exc}") from None
    return tracks


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
    morph_tracks = {}
    if "keyframes" in data:
        tracks, duration, loop = _load_elk(path, data, skeleton)
    elif "tracks" in data:
        tracks, duration, loop = _load_rigedit(path, data, skeleton)
        morph_tracks = _load_morph_tracks(path, data)
    else:
        raise RigFileError(path, "expected a clip with 'tracks' (rigedit) or 'keyframes' (elk), "
                                 "got neither")
    clip_name = optional(data, "name", "")
    clip_name = path.stem if clip_name == "" else name(path, clip_name, "'name'")
    try:
        return Clip(clip_name, skeleton, tracks, duration, loop, morph_tracks)
    except ValueError as exc:
        raise RigFileError(path, str(exc)) from None


def clip_to_dict(clip):
    """rigedit-format dictionary of a clip."""
    tracks = [{"joint": joint, "channel": channel, **bezier_entry(tr)} if tr.curves is not None
              else {"joint": joint, "channel": channel, "interpolation": tr.interpolation,
                    "times": tr.times.round(9).tolist(), "values": tr.values.round(9).tolist()}
              for (joint, channel), tr in clip.tracks.items()]
    for entry, tr in zip(tracks, clip.tracks.values()):
        if tr.interpolation == "cubic_spline":  # glTF's CUBICSPLINE keeps its own tangents
            entry["tangents"] = tr.tangents.reshape(len(tr), -1).round(9).tolist()
    out = {"format": "rigedit.clip", "version": 1, "name": clip.name,
           "duration": clip.duration, "loop": clip.loop, "tracks": tracks}
    if clip.morph_tracks:   # written only when there are some: older files stay as they were
        out["morph_tracks"] = [_morph_track_dict(target, tr)
                               for target, tr in clip.morph_tracks.items()]
    return out


def _morph_track_dict(target, tr):
    entry = {"target": target, "interpolation": tr.interpolation,
             "times": tr.times.round(9).tolist(), "values": tr.values.round(9).tolist()}
    if tr.interpolation == "CUBICSPLINE":
        entry["in_tangents"] = tr.in_tangents.round(9).tolist()
        entry["out_tangents"] = tr.out_tangents.round(9).tolist()
    return entry


def save_clip(path, clip):
    """Write a clip in rigedit's format, atomically."""
    write_json(path, clip_to_dict(clip))
