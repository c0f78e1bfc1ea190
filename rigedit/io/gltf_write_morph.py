"""glTF 2.0 out: morph targets and their weight tracks.

Every primitive of the one mesh gets every target (the spec asks all primitives of a mesh for
the same targets): a target that moves none of a primitive's vertices is an accessor with no
buffer view (zeros, per the spec), one that moves under a third of them a sparse accessor, any
other a dense one. The names go into ``mesh.extras.targetNames`` and the default weights
into ``mesh.weights``.

A clip's weight tracks become one ``weights`` channel on the mesh node (glTF animates all of a
node's weights together), targets without a track holding their default weight:

- tracks that share their key times and interpolation are written as they are (CUBICSPLINE
  with the tracks' own tangents);
- otherwise the channel keys the union of the times. LINEAR and STEP tracks sampled there
  are the same curves; CUBICSPLINE ones are split exactly (a tangent at an inserted time is
  the curve's derivative there); LINEAR mixed with CUBICSPLINE is written as CUBICSPLINE (a
  straight segment is a cubic with the slope for tangents), also exact;
- STEP mixed with another mode is written LINEAR with one extra key a float32 step before
  each step key, so the jump takes that instant: the only inexact case.
"""
from __future__ import annotations

import numpy as np

__all__ = ["primitive_targets", "mesh_morph_fields", "weights_sampler"]

_FLOAT, _USHORT, _UINT = 5126, 5123, 5125
SPARSE_FRACTION = 1 / 3


def _target_accessor(w, deltas, minmax):
    """An accessor of (n, 3) ``deltas``: no buffer view when all zero, sparse when few rows
    move, dense otherwise."""
    d = np.ascontiguousarray(deltas, dtype=np.float32)
    acc = {"componentType": _FLOAT, "count": len(d), "type": "VEC3"}
    if minmax:
        acc["min"] = d.min(axis=0).astype(float).tolist()
        acc["max"] = d.max(axis=0).astype(float).tolist()
    rows = np.flatnonzero(np.any(d != 0, axis=1))
    if len(rows) == 0:
        return w.add("accessors", acc)
    if len(rows) >= SPARSE_FRACTION * len(d):
        return w.accessor(d, vertex=True, target=34962, minmax=minmax)
    itype, dtype = (_USHORT, "<u2") if len(d) <= 65535 else (_UINT, "<u4")
    acc["sparse"] = {"count": len(rows),
                     "indices": {"bufferView": w.view(rows.astype(dtype).tobytes()),
                                 "componentType": itype},
                     "values": {"bufferView": w.view(d[rows].tobytes())}}
    return w.add("accessors", acc)


def primitive_targets(w, morphs, rows):
    """The ``targets`` list of a primitive made of the vertices ``rows`` (n,)."""
    out = []
    for m in range(morphs.count):
        target = {"POSITION": _target_accessor(w, morphs.deltas[m][rows], minmax=True)}
        if morphs.normal_deltas is not None:
            target["NORMAL"] = _target_accessor(w, morphs.normal_deltas[m][rows], minmax=False)
        out.append(target)
    return out


def mesh_morph_fields(morphs):
    """The mesh's ``weights`` and ``extras`` (``targetNames``)."""
    return {"weights": [float(x) for x in morphs.default_weights],
            "extras": {"targetNames": list(morphs.names)}}


def _derivatives(tr, t):
    """(left, right) derivative (weight per second) of a LINEAR or CUBICSPLINE track at
    ``t``: 0 outside its keys (it holds its end values there)."""
    times, values = tr.times, tr.values
    last = len(times) - 1

    def inside(i, u):   # derivative in segment i .. i + 1 at fraction u
        dt = times[i + 1] - times[i]
        if tr.interpolation == "LINEAR":
            return (values[i + 1] - values[i]) / dt
        return (((6 * u * u - 6 * u) * values[i] + (6 * u - 6 * u * u) * values[i + 1]) / dt
                + (3 * u * u - 4 * u + 1) * tr.out_tangents[i]
                + (3 * u * u - 2 * u) * tr.in_tangents[i + 1])

    k = int(np.searchsorted(times, t))
    if k <= last and times[k] == t:
        return (inside(k - 1, 1.0) if k > 0 else 0.0), (inside(k, 0.0) if k < last else 0.0)
    if k == 0 or k > last:
        return 0.0, 0.0
    d = inside(k - 1, (t - times[k - 1]) / (times[k] - times[k - 1]))
    return d, d


def _verbatim(tracks, order, defaults, mode):
    """(K,) times and (K, 3 or 1, M) output of tracks sharing times and mode, as they are."""
    first = next(iter(tracks.values()))
    k = len(first.times)
    vals = np.array([tracks[n].values if n in tracks else np.full(k, d)
                     for n, d in zip(order, defaults)]).T
    if mode != "CUBICSPLINE":
        return first.times, vals[:, None, :]
    zero = np.zeros(k)
    tin = np.array([tracks[n].in_tangents if n in tracks else zero for n in order]).T
    tout = np.array([tracks[n].out_tangents if n in tracks else zero for n in order]).T
    return first.times, np.stack([tin, vals, tout], axis=1)


def _just_before(t):
    """The float32 time one step before ``t`` as the writer rounds it (down)."""
    f = np.float32(t)
    if f > t:
        f = np.nextafter(f, np.float32(-np.inf))
    return float(np.nextafter(f, np.float32(-np.inf)))


def _union(tracks, order, defaults, mode):
    """(K,) times and (K, 3 or 1, M) output keyed at the union of the tracks' times."""
    times = np.unique(np.concatenate([tr.times for tr in tracks.values()]))
    if mode == "LINEAR":   # STEP mixed in: hold the old value until just before its key
        before = [_just_before(t) for tr in tracks.values() if tr.interpolation == "STEP"
                  for t in tr.times[1:]]
        times = np.unique(np.r_[times, before])
    sample = np.array([[tracks[n].sample(t) if n in tracks else d for n, d in
                        zip(order, defaults)] for t in times])
    if mode != "CUBICSPLINE":
        return times, sample[:, None, :]
    tin, tout = np.zeros_like(sample), np.zeros_like(sample)
    for m, n in enumerate(order):
        if n in tracks:
            for i, t in enumerate(times):
                tin[i, m], tout[i, m] = _derivatives(tracks[n], t)
    return times, np.stack([tin, sample, tout], axis=1)


def weights_sampler(clip, morphs):
    """The weights channel of ``clip`` for ``morphs``.

    Returns
    -------
    (times (K,), output (K * per_key * M,), interpolation) or None
        None when the clip has no track for any of the targets.
    """
    tracks = {n: tr for n, tr in clip.morph_tracks.items() if n in morphs.names}
    if not tracks:
        return None
    for n, tr in tracks.items():
        if np.any(tr.times < 0):
            raise ValueError(f"clip {clip.name!r}: glTF key times must be >= 0, got "
                             f"{tr.times.min():g} on morph target {n!r}")
    modes = {tr.interpolation for tr in tracks.values()}
    first = next(iter(tracks.values()))
    same = len(modes) == 1 and all(np.array_equal(tr.times, first.times)
                                   for tr in tracks.values())
    mode = modes.pop() if len(modes) == 1 else "LINEAR" if "STEP" in modes else "CUBICSPLINE"
    build = _verbatim if same else _union
    times, out = build(tracks, morphs.names, morphs.default_weights, mode)
    return times, out.reshape(-1), mode
