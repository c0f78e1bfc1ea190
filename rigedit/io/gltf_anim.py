"""glTF 2.0 in: animations -> clips.

Samplers map to rigedit's interpolation modes exactly: ``STEP`` -> ``step``, ``LINEAR`` ->
``linear`` (translation, scale) or ``slerp`` (rotation, as the spec asks), ``CUBICSPLINE`` ->
``cubic_spline`` with the file's in- and out-tangents kept (not resampled). A ``weights``
channel on a mesh node with morph targets becomes one weight track per target
(:class:`~rigedit.animation.morph_track.WeightTrack`, the same three modes, tangents kept).
Channels on nodes that are not joints, and weight channels on nodes without targets, are
skipped, each kind with one warning. Keys of a
joint below folded non-joint ancestors are mapped through that similarity like its rest
transform (affine on values, linear on tangents, so the curve maps exactly).
"""
from __future__ import annotations

import unicodedata
import warnings

import numpy as np
from scipy.spatial.transform import Rotation

from ..animation.clip import Clip, Track
from ..animation.morph_track import WeightTrack
from ..animation.clip_names import MAX_NAME_LENGTH, check_clip_name, name_key
from ..errors import RigFileError

__all__ = ["read_clips", "weight_tracks", "clip_names", "quat_left_matrix"]

_MODES = {"STEP": {"translation": "step", "rotation": "step", "scale": "step"},
          "LINEAR": {"translation": "linear", "rotation": "slerp", "scale": "linear"},
          "CUBICSPLINE": {"translation": "cubic_spline", "rotation": "cubic_spline",
                          "scale": "cubic_spline"}}
_WIDTH = {"translation": 3, "rotation": 4, "scale": 3}


def clip_names(raw):
    """Valid, unique clip names in order (:mod:`rigedit.animation.clip_names` rules): path
    separators and control characters become ``_``, ``animation_<i>`` for an unnamed one,
    ``_2``, ``_3``... for a repeat (compared ignoring case)."""
    out, used = [], set()
    for i, name in enumerate(raw):
        if isinstance(name, str):
            name = "".join("_" if c in "/\\" or unicodedata.category(c) in ("Cc", "Zl", "Zp")
                           else c for c in name)
            name = name[:MAX_NAME_LENGTH - 8].strip()
        if not isinstance(name, str) or name.strip(" .") == "":
            name = f"animation_{i}"
        new, k = name, 1
        while name_key(new) in used:
            k += 1
            new = f"{name}_{k}"
        used.add(name_key(new))
        out.append(check_clip_name(new))
    return out


def quat_left_matrix(p):
    """(4, 4) matrix of q -> p * q for quaternions (x, y, z, w): linear in q, so it maps
    spline tangents as well as values."""
    x, y, z, w = p
    return np.array([[w, -z, y, x],
                     [z, w, -x, y],
                     [-y, x, w, z],
                     [-x, -y, -z, w]])


def _fold(prefix, channel, values, tangents):
    """Map keys of a channel through a folded similarity ``prefix`` (4, 4)."""
    lin = prefix[:3, :3]
    c = float(np.cbrt(np.linalg.det(lin)))
    if channel == "translation":
        values = values @ lin.T + prefix[:3, 3]
        tangents = None if tangents is None else tangents @ lin.T
    elif channel == "rotation":
        q = quat_left_matrix(Rotation.from_matrix(lin / c).as_quat())
        values = values @ q.T
        tangents = None if tangents is None else tangents @ q.T
    else:
        values = values * c
        tangents = None if tangents is None else tangents * c
    return values, tangents


def _sampler(data, anim, channel, where):
    """(interpolation, (K,) key times, output values as float64) of a channel's sampler,
    checked."""
    samplers = anim.samplers or []
    s = channel.sampler
    if not isinstance(s, int) or not 0 <= s < len(samplers):
        raise RigFileError(data.path, f"{where}: expected a sampler index below {len(samplers)}, "
                                      f"got {s!r}")
    sampler = samplers[s]
    interp = sampler.interpolation or "LINEAR"
    if not isinstance(interp, str) or interp not in _MODES:
        raise RigFileError(data.path, f"{where}: expected interpolation LINEAR, STEP or "
                                      f"CUBICSPLINE, got {interp!r}")
    times = data.accessor(sampler.input, f"{where} input")
    if times.shape[1] != 1 or times.dtype.kind != "f":
        raise RigFileError(data.path, f"{where}: expected float SCALAR key times")
    times = times[:, 0]
    if not np.all(np.isfinite(times)) or np.any(np.diff(times) <= 0):
        raise RigFileError(data.path, f"{where}: expected finite, strictly increasing key "
                                      "times, got NaN or a repeated/decreasing time")
    values = np.asarray(data.accessor(sampler.output, f"{where} output"), dtype=np.float64)
    return interp, times, values


def weight_tracks(data, anim_index, anim, channel, ci, names):
    """``{target name: WeightTrack}`` of a ``weights`` channel on a node whose targets are
    ``names``: the output holds, per key, one weight per target (CUBICSPLINE: in-tangents,
    values, out-tangents, each a block of one per target)."""
    where = f"animation {anim_index} channel {ci}"
    interp, times, values = _sampler(data, anim, channel, where)
    per_key = 3 if interp == "CUBICSPLINE" else 1
    m = len(names)
    if values.shape != (len(times) * per_key * m, 1):
        raise RigFileError(data.path, f"{where}: expected {len(times) * per_key * m} SCALAR "
                                      f"weights ({m} targets), got {values.shape}")
    if not np.all(np.isfinite(values)):
        raise RigFileError(data.path, f"{where}: expected finite weights, got NaN or inf")
    v = values.reshape(len(times), per_key, m)
    mid = 1 if per_key == 3 else 0
    out = {}
    try:
        for i, name in enumerate(names):
            tangents = (v[:, 0, i], v[:, 2, i]) if per_key == 3 else (None, None)
            out[name] = WeightTrack(times, v[:, mid, i], interp, *tangents)
    except ValueError as exc:
        raise RigFileError(data.path, f"{where}: {exc}") from None
    return out


def _channel_track(data, anim_index, anim, channel, ci, prefix):
    where = f"animation {anim_index} channel {ci}"
    path = channel.target.path
    interp, times, values = _sampler(data, anim, channel, where)
    width = _WIDTH[path]
    per_key = 3 if interp == "CUBICSPLINE" else 1
    if values.shape != (len(times) * per_key, width):
        raise RigFileError(data.path, f"{where}: expected {len(times) * per_key} {path} values "
                                      f"of width {width}, got {values.shape}")
    if not np.all(np.isfinite(values)):
        raise RigFileError(data.path, f"{where}: expected finite values, got NaN or inf")
    tangents = None
    if per_key == 3:
        v = values.reshape(len(times), 3, width)
        values, tangents = v[:, 1], v[:, [0, 2]]
    if prefix is not None:
        values, tangents = _fold(prefix, path, values, tangents)
    try:
        return Track(path, times, values, _MODES[interp][path], tangents)
    except ValueError as exc:
        raise RigFileError(data.path, f"{where}: {exc}") from None


def read_clips(data, skeleton, smap, warning, morph_nodes=None):
    """Every animation of the file as a :class:`Clip` on ``skeleton``.

    Parameters
    ----------
    morph_nodes : dict[int, list[str]], optional
        Mesh node -> the names of its morph targets: its ``weights`` channels become one
        weight track per target.

    Returns
    -------
    clips : dict[str, Clip]
    """
    anims = data.gltf.animations or []
    names = clip_names([a.name for a in anims])
    morph_nodes = morph_nodes or {}
    clips, off_skeleton, morph = {}, set(), 0
    for a, (name, anim) in enumerate(zip(names, anims)):
        tracks, weights = {}, {}
        for ci, channel in enumerate(anim.channels or []):
            target = channel.target
            if target is None or target.node is None:
                continue
            nodes = len(data.gltf.nodes or [])
            if not isinstance(target.node, int) or not 0 <= target.node < nodes \
                    or not isinstance(target.path, str):
                raise RigFileError(data.path, f"animation {a} channel {ci}: expected a target "
                                              f"node below {nodes} and a path, got "
                                              f"{target.node!r} and {target.path!r}")
            if target.path == "weights":
                if target.node in morph_nodes:
                    weights.update(weight_tracks(data, a, anim, channel, ci,
                                                 morph_nodes[target.node]))
                else:
                    morph += 1
                continue
            if target.path not in _WIDTH:
                raise RigFileError(data.path, f"animation {a} channel {ci}: expected a target "
                                              f"path translation, rotation, scale or weights, "
                                              f"got {target.path!r}")
            j = smap.of_node.get(target.node)
            if j is None:
                off_skeleton.add(target.node)
                continue
            tracks[(skeleton.names[j], target.path)] = _channel_track(
                data, a, anim, channel, ci, smap.prefix[j])
        # rigedit's own exports keep the clip's length and loop flag in the animation's extras
        own = anim.extras.get("rigedit") if isinstance(anim.extras, dict) else None
        own = own if isinstance(own, dict) else {}
        duration = own.get("duration")
        last = max((tr.times[-1] for tr in (*tracks.values(), *weights.values())),
                   default=0.0)
        if not isinstance(duration, (int, float)) or not last <= duration < 1e9:
            duration = None
        clips[name] = Clip(name, skeleton, tracks, duration=duration,
                           loop=bool(own.get("loop", True)), morph_tracks=weights)
    if off_skeleton:
        warnings.warn(f"{data.path}: skipped animation channels on {len(off_skeleton)} nodes "
                      f"that are not joints of the skin (nodes {sorted(off_skeleton)[:8]})",
                      warning, stacklevel=3)
    if morph:
        warnings.warn(f"{data.path}: skipped {morph} morph-target weight channels on nodes "
                      "without morph targets", warning, stacklevel=3)
    return clips
