"""glTF 2.0 out, compact: compressed clips' reduced keys in glTF core (issue 20).

The clips come in as plain :class:`~rigedit.animation.clip.Clip` objects whose keys are the
compressor's (:meth:`rigedit.compression` results' ``to_clip()``: reduced keys, values as
decoded). What is written, all glTF 2.0 core so every viewer opens it:

- the keys as they are: ``step`` -> STEP, ``linear``/``slerp`` -> LINEAR, ``cubic_spline`` and
  ``catmull_rom`` -> CUBICSPLINE with the tangents (the same curve). ``nlerp``/``hybrid``
  rotations are refused: glTF's LINEAR is slerp, and resampling them (as the plain writer
  does) would undo the key reduction; the compressor's glTF target makes slerp keys.
- rotation outputs as normalised SHORT (componentType 5122, ``normalized: true``, which the
  core spec allows for rotation outputs): 8 bytes a key instead of 16. A CUBICSPLINE rotation
  whose tangents leave [-1, 1] stays float32 (a normalised integer cannot hold them).
  Translations and scales are float32 (the spec allows nothing else for them).
- one time accessor per distinct list of key times (float32 bytes), shared by every sampler
  with those times, across clips too.
- every animation keys the same channels (:func:`same_channels`): a channel at its rest in
  every clip is left out (the node stays at rest), one that moves in some clip is keyed in
  all, with one key at the rest (float32, exact) where a clip leaves it at rest; another
  one-key track is written as one key.
- a clip whose keys all end before its duration gets a hold key at the duration on one
  LINEAR/STEP sampler, so viewers that take an animation's length from its keys play it for
  its whole duration (rigedit reads ``extras.rigedit.duration``).

With ``meshopt=True`` the buffer views are also compressed with ``EXT_meshopt_compression``
(meshoptimizer's lossless vertex and index codecs, through the ``meshopt`` package, extra
``rigedit[meshopt]``), declared in ``extensionsRequired``: :func:`meshopt_buffers`.

Hooked into :func:`rigedit.io.gltf_write.gltf_bytes` through its ``compact`` argument: the
mesh, skin and nodes are the plain writer's; only the animations (and, with meshopt, the
buffers) are this module's.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..animation.clip import Clip, Track
from ..errors import RigFileError

__all__ = ["CompactAnimations", "save_gltf_compressed", "meshopt_available", "decoded_rows",
           "same_channels", "is_rest", "rest_value", "MESHOPT"]

MESHOPT = "EXT_meshopt_compression"
_FLOAT, _SHORT = 5126, 5122
#: Normalised SHORT: value = max(c / 32767, -1) (glTF 2.0, "Animations").
_SHORT_SCALE = 32767.0
#: A one-key track within this of the rest value (float32 rounding of the node's TRS) is
#: the rest.
REST_TOLERANCE = 1e-7


def meshopt_available():
    """Whether the ``meshopt`` package (meshoptimizer's codecs) imports."""
    try:
        import meshopt  # noqa: F401
    except ImportError:
        return False
    return True


def _kind(track):
    """glTF interpolation of a track; ``ValueError`` for one glTF cannot hold as keys."""
    mode = track.interpolation
    if mode == "step":
        return "STEP"
    if mode in ("linear", "slerp") or len(track.times) == 1:
        return "LINEAR"
    if mode in ("cubic_spline", "catmull_rom"):
        return "CUBICSPLINE"
    raise ValueError(f"a {mode} {track.channel} track cannot be written as glTF keys "
                     "(glTF's LINEAR rotation is slerp); compress with target='gltf'")


def _outputs(track, kind):
    """(N, C) float64 output rows: the values, or in-tangent, value, out-tangent per key."""
    if kind != "CUBICSPLINE":
        return track.values
    tan = track.tangents if track.interpolation == "cubic_spline" else \
        np.repeat(track.tangents[:, None], 2, axis=1)
    return np.stack([tan[:, 0], track.values, tan[:, 1]], axis=1).reshape(
        -1, track.values.shape[1])


def _shorts(channel, rows):
    """(N, 4) int16 of rotation output rows when they fit normalised SHORT, else None."""
    if channel != "rotation" or np.abs(rows).max() > 1.0:
        return None
    return np.clip(np.round(rows * _SHORT_SCALE), -32767, 32767).astype("<i2")


def decoded_rows(track, exact=False):
    """``(glTF interpolation, (N, C) output rows as a reader decodes them)`` of what the writer
    stores for ``track`` (normalised SHORT rotations, float32 otherwise; float32 for all when
    ``exact``: a one-key track at the rest)."""
    kind = _kind(track)
    rows = _outputs(track, kind)
    ints = None if exact else _shorts(track.channel, rows)
    if ints is not None:
        return kind, np.maximum(ints / _SHORT_SCALE, -1.0)
    return kind, rows.astype(np.float32).astype(np.float64)


def rest_value(skeleton, joint, channel):
    """The rest value of one channel of one joint."""
    return getattr(skeleton, f"rest_{channel}")[skeleton.joint_index(joint)]


def is_rest(track, rest):
    """Whether a one-key track holds the node's rest value (a rotation up to its sign)."""
    if len(track.times) != 1:
        return False
    v = track.values[0]
    if track.channel == "rotation":
        return min(np.abs(v - rest).max(), np.abs(v + rest).max()) <= REST_TOLERANCE
    return np.abs(v - rest).max() <= REST_TOLERANCE


def same_channels(clips):
    """Every clip with the same channels: those that hold something other than the rest in
    some clip (a channel at its rest everywhere is left out); a clip without one of them, or
    with it at the rest, gets one key at the rest. When no channel holds anything but the rest,
    every clip keys its root's rotation at the rest (a glTF animation has at least one
    channel).

    Why: a viewer that plays one animation after another may keep, on a channel the new one
    does not key, what the old one left there (Blender does); the spec's "the node's own TRS"
    then only holds if every animation keys the same channels. One rest key costs 8-16
    bytes and a shared one-float time accessor.
    """
    keyed = {}
    for clip in clips.values():
        for (joint, channel), tr in clip.tracks.items():
            if not is_rest(tr, rest_value(clip.skeleton, joint, channel)):
                keyed.setdefault((joint, channel), None)
    if not keyed and clips:
        # every clip at its rest: an animation needs a channel (one without any is no glTF
        # animation, and the clip would be lost), so each keys its root's rotation at rest
        keyed[(next(iter(clips.values())).skeleton.names[0], "rotation")] = None
    out = {}
    for name, clip in clips.items():
        sk = clip.skeleton
        tracks = {key: clip.tracks.get(key) or Track(key[1], [0.0], [rest_value(sk, *key)])
                  for key in keyed}
        out[name] = Clip(clip.name, sk, tracks, clip.duration, clip.loop, clip.morph_tracks)
    return out


class CompactAnimations:
    """Writes compressed clips as glTF animations into :mod:`rigedit.io.gltf_write`'s buffer.

    Parameters
    ----------
    clips : dict[str, Clip]
        Clip name -> plain clip of reduced keys (its skeleton's joint names are the rig's).
    meshopt : bool
        Compress the buffer views with ``EXT_meshopt_compression`` too.
    float_clips : iterable of str
        Clips whose rotations are written float32 (where the int16 grid alone errs more than
        the bound: :mod:`rigedit.io.gltf_compress`).
    """

    def __init__(self, clips, meshopt=False, float_clips=()):
        if meshopt and not meshopt_available():
            raise ValueError("--meshopt needs the meshopt package (pip install "
                             "'rigedit[meshopt]')")
        self.clips = dict(clips)
        self.meshopt = bool(meshopt)
        self.float_clips = set(float_clips)
        self._times = {}        # float32 key-time bytes -> accessor index
        self._clip = None       # the clip being written
        self._views = []        # (buffer view, clip name, kind) of the animation data
        self._doc = None

    # ------------------------------------------------------------------ accessors
    def _input(self, w, times):
        from .gltf_write import _float32_times

        t32 = _float32_times(times)
        key = t32.tobytes()
        if key not in self._times:
            self._times[key] = self._note(w, w.accessor(t32[:, None], minmax=True), "times")
        return self._times[key]

    def _note(self, w, accessor, kind):
        """Remember the accessor's view as animation data of the current clip."""
        self._views.append((w.doc["accessors"][accessor]["bufferView"], self._clip, kind))
        return accessor

    def _output(self, w, channel, rows, exact=False):
        ints = None if exact else _shorts(channel, rows)
        if ints is not None:
            acc = {"bufferView": w.view(ints.tobytes()), "componentType": _SHORT,
                   "normalized": True, "count": len(ints), "type": "VEC4"}
            return self._note(w, w.add("accessors", acc), channel)
        return self._note(w, w.accessor(rows), channel)

    def bytes_by_clip(self):
        """``{clip name: {kind: bytes}}`` of the animation data written (after :meth:`finish`:
        the bytes as stored, meshopt-compressed where it is); a time accessor shared by
        several clips counts in the first."""
        out = {name: dict.fromkeys(("rotation", "translation", "scale", "times"), 0)
               for name in self.clips}
        for view, clip, kind in self._views:
            v = self._doc["bufferViews"][view]
            ext = v.get("extensions", {}).get(MESHOPT)
            out[clip][kind] += ext["byteLength"] if ext else v["byteLength"]
        return out

    # ------------------------------------------------------------------ animations
    def _sampler(self, w, track, end, exact):
        kind = _kind(track)
        times, rows = track.times, _outputs(track, kind)
        if end is not None:    # a hold key at the clip's end: the same curve, the whole length
            times, rows = np.r_[times, end], np.vstack([rows, rows[-1:]])
        return {"input": self._input(w, times),
                "output": self._output(w, track.channel, rows, exact),
                "interpolation": kind}

    def write(self, w, rig, joints, mesh_node=None):
        """Add one animation per clip to the writer ``w`` (``joints``: the joint nodes)."""
        from .gltf_write import clip_animation

        self._doc = w.doc
        for name, clip in same_channels(self.clips).items():
            self._clip = name
            sk = clip.skeleton
            # a rest key is written float32, exactly (it was never quantised)
            exact = {id(tr) for key, tr in clip.tracks.items()
                     if name in self.float_clips or is_rest(tr, rest_value(sk, *key))}
            last = max((tr.times[-1] for tr in clip.tracks.values()), default=0.0)
            holder = None
            if clip.duration > last + 1e-6:
                holder = next((tr for tr in clip.tracks.values() if _kind(tr) != "CUBICSPLINE"
                               and tr.times[-1] == last), None)
            clip_animation(w, rig, name, clip, joints, mesh_node,
                           lambda w, tr, exact=exact, holder=holder, end=clip.duration:
                           self._sampler(w, tr, end if tr is holder else None,
                                         id(tr) in exact))

    def finish(self, w):
        """Rewrite the buffers once everything is written (meshopt), else nothing."""
        if self.meshopt:
            meshopt_buffers(w)


# ---------------------------------------------------------------------- meshopt
def _view_uses(doc):
    """bufferView index -> (mode, element byte size, count) for the views meshopt can take:
    index views (TRIANGLES for triangle lists, else INDICES) and views read by accessors
    whose elements are 4-256 bytes in fours (ATTRIBUTES); other views (images, sparse
    indices, 1- and 2-byte rows) are left as they are."""
    tri_indices = {p["indices"] for m in doc.get("meshes", []) for p in m["primitives"]
                   if "indices" in p and p.get("mode", 4) == 4}
    size = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
    width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
    readers = {}
    for i, acc in enumerate(doc["accessors"]):
        if "bufferView" in acc:
            readers.setdefault(acc["bufferView"], []).append((i, acc))
    uses = {}
    for v, accs in readers.items():
        if len(accs) != 1:
            continue
        i, acc = accs[0]
        view = doc["bufferViews"][v]
        elem = size[acc["componentType"]] * width[acc["type"]]
        stride = view.get("byteStride", elem)
        if acc.get("byteOffset", 0) or view["byteLength"] != stride * acc["count"]:
            continue
        if view.get("target") == 34963:
            mode = "TRIANGLES" if i in tri_indices and acc["count"] % 3 == 0 else "INDICES"
            if elem in (2, 4):
                uses[v] = (mode, elem, acc["count"])
        elif stride % 4 == 0 and 4 <= stride <= 256:
            uses[v] = ("ATTRIBUTES", stride, acc["count"])
    return uses


def _encoded(meshopt, data, mode, stride, count):
    """One view's bytes through meshoptimizer's codec for ``mode``."""
    if mode == "ATTRIBUTES":
        rows = np.frombuffer(data, np.uint8).reshape(count, stride)
    else:
        rows = np.frombuffer(data, {2: "<u2", 4: "<u4"}[stride])
    return meshopt.encode_gltf_buffer(rows, mode)


def meshopt_buffers(w):
    """Move the writer's views into ``EXT_meshopt_compression``: buffer 0 (the GLB's BIN chunk
    or the data URI) holds the compressed views and the ones left as they are (images, views
    meshopt cannot take or does not make smaller); buffer 1 is the extension's fallback buffer
    (no data: the extension is required)."""
    import meshopt

    doc, old = w.doc, bytes(w.blob)
    uses = _view_uses(doc)
    blob, fallback = bytearray(), 0
    for v, view in enumerate(doc["bufferViews"]):
        data = old[view["byteOffset"]:view["byteOffset"] + view["byteLength"]]
        blob += bytes((-len(blob)) % 4)
        packed = _encoded(meshopt, data, *uses[v]) if v in uses else None
        if packed is None or len(packed) >= len(data):   # a tiny view: no gain
            view["byteOffset"] = len(blob)
            blob += data
            continue
        mode, stride, count = uses[v]
        ext = {"buffer": 0, "byteOffset": len(blob), "byteLength": len(packed),
               "byteStride": stride, "count": count, "mode": mode}
        blob += packed
        fallback += (-fallback) % 4
        view.update(buffer=1, byteOffset=fallback)
        view.setdefault("extensions", {})[MESHOPT] = ext
        fallback += view["byteLength"]
    blob += bytes((-len(blob)) % 4)
    w.blob = blob
    doc["buffers"] = [{"byteLength": len(blob)},
                      {"byteLength": max(fallback, 4), "extensions": {MESHOPT: {"fallback": True}}}]
    for key in ("extensionsUsed", "extensionsRequired"):
        if MESHOPT not in doc.setdefault(key, []):
            doc[key].append(MESHOPT)


def save_gltf_compressed(rig, path, clips, meshopt=False):
    """Write ``rig`` with ``clips`` (compressed, reduced keys) as compact glTF, atomically.

    Parameters
    ----------
    rig : RigData or Rig
        Mesh, skin and skeleton come from here; its own clips are not written.
    path : str or Path
        ``.glb`` or ``.gltf``.
    clips : dict[str, Clip]
        Clip name -> plain clip of the compressor's keys (``result.clips[name].to_clip()``).
    meshopt : bool
        Also compress the buffers with ``EXT_meshopt_compression`` (required by the file).

    Returns
    -------
    CompactAnimations
        What was written (:meth:`CompactAnimations.bytes_by_clip`).

    Raises
    ------
    RigFileError
        For another extension or data glTF cannot hold, naming the file.
    """
    from .gltf_write import save_gltf

    try:
        compact = CompactAnimations(clips, meshopt=meshopt)
    except ValueError as exc:
        raise RigFileError(Path(path), str(exc)) from None
    save_gltf(rig, path, compact=compact)
    return compact
