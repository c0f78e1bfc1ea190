"""FBX in: every animation stack as a clip, baked by ufbx at the file's frame rate.

ufbx evaluates each stack's curves (all layers, pre/post rotations, pivots and rotation
orders included) into local translation, rotation and scale keys per node at the file's
frame rate, plus the curves' own key times (``bake_anim``; its key reduction off; at most
:data:`MAX_BAKED_KEYS` keys, checked before baking). rigedit
then drops only the keys that the interpolation of their neighbours reproduces within
:data:`EXACT` (linear for vectors, slerp for rotations), so sampling at any baked time gives
the baked value. Keys of a joint below folded non-joint nodes are mapped through that
similarity, like its rest transform.
"""
from __future__ import annotations

import numpy as np

from ..animation.clip import Clip, Track
from ..animation.morph_track import WeightTrack
from ..errors import RigFileError
from .fbx_read_scene import call, ufbx_module
from .gltf_anim import clip_names, quat_left_matrix
from .jsonfile import MAX_SECONDS

__all__ = ["bake_stacks", "animated_nodes", "clips_of", "weight_tracks", "reduce_keys",
           "EXACT"]

#: Most keys a take may bake to (animated values times frames of the file's time range):
#: 5 million is a 9-minute take of 100 joints at 30 frames per second; reading costs about
#: 400 bytes a key while the take is converted (ufbx's keys are Python objects until then).
MAX_BAKED_KEYS = 5_000_000

#: A key is dropped when its neighbours' interpolation gives it within this (file units
#: after conversion: metres, unit quaternion components, scale factors).
EXACT = 1e-9


def _interpolate(channel, a, b, u):
    """Values between keys ``a`` and ``b`` (K, C) at fractions ``u`` (K,): linear, or for
    rotations the slerp of :func:`rigedit.animation.interpolate.slerp` row by row (``b`` on
    ``a``'s hemisphere already)."""
    u = u[:, None]
    if channel != "rotation":   # translation, scale, a morph target's weight
        return a + (b - a) * u
    dot = np.clip(np.sum(a * b, axis=1, keepdims=True), -1.0, 1.0)
    theta = np.arccos(dot)
    sin = np.sin(theta)
    small = sin < 1e-9
    safe = np.where(small, 1.0, sin)
    out = np.where(small, a + (b - a) * u,
                   (np.sin((1 - u) * theta) * a + np.sin(u * theta) * b) / safe)
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def _greedy(channel, times, values, tol):
    """:func:`reduce_keys` one key at a time (for the stretches its fast pass cannot settle)."""
    keep = [0]
    for i in range(1, len(times) - 1):
        a, b = keep[-1], i + 1
        inner = np.arange(a + 1, b)
        u = (times[inner] - times[a]) / (times[b] - times[a])
        guess = _interpolate(channel, np.repeat(values[a:a + 1], len(inner), 0),
                             np.repeat(values[b:b + 1], len(inner), 0), u)
        if np.any(np.abs(guess - values[inner]) > tol):
            keep.append(i)
    keep.append(len(times) - 1)
    return np.array(keep)


def _gaps_wrong(channel, times, values, keep, tol):
    """Kept-key positions ``g`` whose gap ``keep[g - 1] .. keep[g]`` misses a dropped key."""
    dropped = np.setdiff1d(np.arange(len(times)), keep)
    if not len(dropped):
        return np.zeros(0, np.int64)
    g = np.searchsorted(keep, dropped)
    a, b = keep[g - 1], keep[g]
    u = (times[dropped] - times[a]) / (times[b] - times[a])
    bad = np.any(np.abs(_interpolate(channel, values[a], values[b], u) - values[dropped]) > tol,
                 axis=1)
    return np.unique(g[bad])


def reduce_keys(channel, times, values, tol=EXACT):
    """Indices of the keys to keep: a key goes only when the interpolation between the kept
    keys around it reproduces it within ``tol`` (every dropped key is checked against the
    kept keys that end up around it).

    Keys whose neighbours reproduce them are dropped in one pass; each gap that leaves is
    then checked whole, and a gap that misses a dropped key is reduced key by key.

    Parameters
    ----------
    channel : {"translation", "rotation", "scale"}
    times : (K,) float
    values : (K, C) float
        Rotations as unit quaternions on one hemisphere (each key next to its predecessor).

    Returns
    -------
    keep : (M,) int
        Always the first key; the last one unless the track is constant (then one key).
    """
    n = len(times)
    if n <= 1 or np.all(np.abs(values - values[0]) <= tol):
        return np.array([0])
    if n == 2:
        return np.array([0, 1])
    u = (times[1:-1] - times[:-2]) / (times[2:] - times[:-2])
    mid = _interpolate(channel, values[:-2], values[2:], u)
    drop = np.all(np.abs(mid - values[1:-1]) <= tol, axis=1)
    keep = np.concatenate([[0], 1 + np.flatnonzero(~drop), [n - 1]])
    wrong = _gaps_wrong(channel, times, values, keep, tol)
    if len(wrong):
        parts = [keep]
        for g in wrong:
            a, b = keep[g - 1], keep[g]
            parts.append(a + _greedy(channel, times[a:b + 1], values[a:b + 1], tol))
        keep = np.unique(np.concatenate(parts))
    return keep


def _keys(keys, width):
    times = np.array([k.time for k in keys], dtype=np.float64)
    values = np.array([tuple(k.value) for k in keys], dtype=np.float64).reshape(-1, width)
    return times, values


def _fold(prefix, channel, values):
    """Keys mapped through a folded similarity ``prefix`` (4, 4) (see :mod:`.gltf_anim`)."""
    lin = prefix[:3, :3]
    c = float(np.cbrt(np.linalg.det(lin)))
    if channel == "translation":
        return values @ lin.T + prefix[:3, 3]
    if channel == "rotation":
        from scipy.spatial.transform import Rotation

        return values @ quat_left_matrix(Rotation.from_matrix(lin / c).as_quat()).T
    return values * c


def _track(channel, times, values, prefix, shift):
    if prefix is not None:
        values = _fold(prefix, channel, values)
    if channel == "rotation":
        values = values / np.linalg.norm(values, axis=1, keepdims=True)
        flips = np.cumprod(np.where(np.sum(values[1:] * values[:-1], axis=1) < 0, -1.0, 1.0))
        values[1:] *= flips[:, None]
    keep = reduce_keys(channel, times, values)
    return Track(channel, times[keep] + shift, values[keep],
                 "slerp" if channel == "rotation" else "linear")


def bake_stacks(scene, keep, fps, path):
    """Every animation stack baked by ufbx: a list of ``(name, begin, end, nodes,
    elements)`` with ``nodes`` node typed id -> channel -> ((K,) times, (K, C) local values)
    and ``elements`` element id -> animated property -> ((K,) times, (K,) first components).

    Parameters
    ----------
    scene : Held
    keep : list
        The read's keep-alive list (:mod:`.fbx_read_scene`).
    fps : float
        The file's frame rate (a key at every frame).
    path : Path
        For the messages: times beyond :data:`~rigedit.io.jsonfile.MAX_SECONDS` and more than
        :data:`MAX_BAKED_KEYS` keys to bake are errors.
    """
    ufbx = ufbx_module()
    stacks = scene.anim_stacks
    out = []
    times = [t for c in scene.anim_curves for t in (float(c.min_time), float(c.max_time))]
    times += [t for s in stacks for t in (float(s.time_begin), float(s.time_end))]
    if not all(abs(t) <= MAX_SECONDS for t in times):
        raise RigFileError(path, f"expected animation times within {MAX_SECONDS:g} s, got "
                                 f"{max(times, key=abs):g}")
    curve_span = max(times, default=0.0) - min(times, default=0.0)
    for name, stack in zip(clip_names([s.name for s in stacks]), stacks):
        # what baking will make is bounded before ufbx makes it: a key per frame of the
        # file's whole time range for every animated value of the take
        frames = curve_span * fps
        values = sum(len(layer.anim_values) for layer in stack.layers)
        if frames * max(values, 1) > MAX_BAKED_KEYS:
            raise RigFileError(path, f"take {name!r}: expected at most {MAX_BAKED_KEYS} keys to "
                                     f"bake, got {values} animated values over {frames:.0f} "
                                     "frames")
        # ufbx samples a key interval at most max_keyframe_segments times (30 by default:
        # a bezier curve keyed every 10 s would get no key at most frames)
        segments = int(max(32, np.ceil(frames) + 1))
        bake = call(ufbx.bake_anim, scene, stack.anim, keep=keep, resample_rate=fps,
                    minimum_sample_rate=fps, key_reduction_enabled=False,
                    trim_start_time=False, max_keyframe_segments=segments)
        nodes = {}
        for baked in bake.nodes:
            nodes[baked.typed_id] = {
                channel: _keys(keys, 4 if channel == "rotation" else 3)
                for channel, keys in (("translation", baked.translation_keys),
                                      ("rotation", baked.rotation_keys),
                                      ("scale", baked.scale_keys)) if len(keys)}
        elements = {}
        for baked in bake.elements:     # blend shape channels' weights (DeformPercent)
            elements[baked.element_id] = {
                prop.name: tuple(a[:, 0] if a.ndim == 2 else a for a in _keys(prop.keys, 3))
                for prop in baked.props if len(prop.keys)}
        begin = min(float(stack.time_begin), float(bake.key_time_min))
        out.append((name, begin, float(stack.time_end), nodes, elements))
    return out


def animated_nodes(stacks, rest):
    """Typed ids of the nodes some stack moves away from their rest ``rest`` (typed id ->
    {channel: (C,) value})."""
    moved = set()
    for _name, _begin, _end, nodes, _elements in stacks:
        for node, channels in nodes.items():
            for channel, (_times, values) in channels.items():
                ref = rest[node][channel]
                if channel == "rotation":   # q and -q are one rotation
                    ref = ref * np.where(values @ ref < 0, -1.0, 1.0)[:, None]
                if np.any(np.abs(values - ref) > EXACT):
                    moved.add(node)
    return moved


def clips_of(stacks, skeleton, joint_of_node, prefix, channels=None):
    """The baked stacks as clips on ``skeleton``.

    Parameters
    ----------
    stacks : list
        :func:`bake_stacks`'s.
    skeleton : Skeleton
    joint_of_node : dict[int, int]
        Node typed id -> joint index.
    prefix : list
        Per joint, the (4, 4) folded similarity of non-joint ancestors, or None.
    channels : dict[str, list[int]], optional
        Morph target name -> element ids of its blend shape channels (weight tracks).

    Returns
    -------
    clips : dict[str, Clip]
    shifts : dict[str, float]
        Seconds added to the key times of the clips of stacks that start before 0 (so that
        no key has a negative time); the file's times elsewhere.
    """
    clips, shifts = {}, {}
    for name, begin, end, nodes, elements in stacks:
        shift = max(0.0, -begin)
        if shift:
            shifts[name] = shift
        tracks = {}
        for node, keyed in nodes.items():
            j = joint_of_node.get(node)
            if j is None:
                continue
            for channel, (times, values) in keyed.items():
                tracks[(skeleton.names[j], channel)] = _track(channel, times, values,
                                                              prefix[j], shift)
        morph = weight_tracks(elements, channels or {}, shift)
        last = max((tr.times[-1] for tr in [*tracks.values(), *morph.values()]), default=0.0)
        clips[name] = Clip(name, skeleton, tracks, duration=max(end + shift, last), loop=True,
                           morph_tracks=morph)
    return clips, shifts


def weight_tracks(elements, channels, shift):
    """Weight tracks of one baked stack: target name -> :class:`WeightTrack` (the first of
    its channels that the stack animates), keys reduced where exact.

    Parameters
    ----------
    elements : dict[int, dict[str, ((K,) times, (K,) values)]]
        Baked element id -> property name -> keys (``DeformPercent``, 0..100).
    channels : dict[str, list[int]]
    shift : float
        Seconds added to every key time.
    """
    tracks = {}
    for name, ids in channels.items():
        keys = next((elements[e]["DeformPercent"] for e in ids
                     if "DeformPercent" in elements.get(e, {})), None)
        if keys is None:
            continue
        times, values = keys
        values = values / 100.0
        keep = reduce_keys("weight", times, values[:, None])
        tracks[name] = WeightTrack(times[keep] + shift, values[keep], "LINEAR")
    return tracks
