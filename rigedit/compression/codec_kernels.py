"""The decoder's compiled kernels (numba): one pose, or a batch of poses, straight from the
packed words, one loop over the animated tracks (a binary search in the track's key times,
two keys' fields read (four for a track of Catmull-Rom keys), dequantised, the dropped
component rebuilt, LERP / NLERP or the cubic).

Imported only by :func:`rigedit.compression.codec.kernels` (which imports numba through
this module, once, on first use, and caches the compiled code on disk with
``cache=True``); :class:`~rigedit.compression.codec.ClipDecoder`'s numpy path is the
reference and the fallback (``RIGEDIT_NO_NUMBA=1``). The tables are built by the decoder:

``itab`` (T, 7) int64 per animated track: key start, key count, lead bits (2 for per-key
rotations), is-rotation, target column (joint * 10 + first column), fixed dropped component,
is-cubic;
``sitab`` (S, 9) int64 per segment of stored keys (a whole track when not segmented): bit
offset of its first key, that key's index in its track, stride, the three fields' offsets,
the three fields' bits; ``sftab`` (S, 6) float64: lo (3), scale (3); ``key_seg`` (K,) each
key's segment.
"""
from __future__ import annotations

import numba
import numpy as np

from .reduce_kernels import cubic_component

__all__ = ["pose_at", "poses_at"]

_OTHERS = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]], dtype=np.int64)


@numba.njit(cache=True, inline="always")
def _field(words, pos, bits):
    w = pos >> 5
    pair = words[w] | (words[w + 1] << np.uint64(32))
    return (pair >> np.uint64(pos & 31)) & ((np.uint64(1) << np.uint64(bits)) - np.uint64(1))


@numba.njit(cache=True)
def _decode_key(words, itab, sitab, sftab, key_seg, k, gkey, others, q):
    """Key ``gkey`` (global index) of track ``k`` into q[0:3] (vector) or q[0:4] (rotation)."""
    g = key_seg[gkey]
    pos = sitab[g, 0] + (gkey - itab[k, 0] - sitab[g, 1]) * sitab[g, 2]
    dropped = itab[k, 5]
    if itab[k, 2]:
        dropped = np.int64(_field(words, pos, 2))
    rotation = itab[k, 3] != 0
    w2 = 1.0
    for m in range(3):
        c = sftab[g, m] + np.float64(_field(words, pos + sitab[g, 3 + m], sitab[g, 6 + m])) \
            * sftab[g, 3 + m]
        if rotation:
            q[others[dropped, m]] = c
            w2 -= c * c
        else:
            q[m] = c
    if rotation:
        q[dropped] = np.sqrt(w2) if w2 > 0 else 0.0


@numba.njit(cache=True)
def _align(q, ref):
    """q[0:4] onto the hemisphere of ref[0:4], in place."""
    d = q[0] * ref[0] + q[1] * ref[1] + q[2] * ref[2] + q[3] * ref[3]
    if d < 0:
        for m in range(4):
            q[m] = -q[m]


@numba.njit(cache=True)
def _pose(t, itab, sitab, sftab, key_seg, key_times, words, others, out, a, last, keys):
    """One pose into ``out``; ``last`` (T,) the span each track decoded last and ``keys``
    (T, 4, 4) its keys i-1 .. i+2 (clamped to the track; a linear track uses i and i+1),
    reused when ``t`` falls in the same span (a batch of times, playback frame after frame).
    ``a`` (4,) scratch."""
    for k in range(itab.shape[0]):
        first = itab[k, 0]
        lo = first
        hi = lo + itab[k, 1] - 1
        end = hi
        if t <= key_times[lo]:
            i, u = lo, 0.0
        elif t >= key_times[hi]:
            i, u = hi - 1, 1.0
        else:
            while hi - lo > 1:
                mid = (lo + hi) >> 1
                if key_times[mid] <= t:
                    lo = mid
                else:
                    hi = mid
            i = lo
            u = (t - key_times[i]) / (key_times[i + 1] - key_times[i])
        cubic = itab[k, 6] != 0
        rotation = itab[k, 3] != 0
        i0 = i - 1 if i > first else i
        i3 = i + 2 if i + 2 <= end else i + 1
        if last[k] != i:
            if cubic:
                _decode_key(words, itab, sitab, sftab, key_seg, k, i0, others, keys[k, 0])
                _decode_key(words, itab, sitab, sftab, key_seg, k, i3, others, keys[k, 3])
            _decode_key(words, itab, sitab, sftab, key_seg, k, i, others, keys[k, 1])
            _decode_key(words, itab, sitab, sftab, key_seg, k, i + 1, others, keys[k, 2])
            if rotation:      # the neighbours on their predecessor's hemisphere
                _align(keys[k, 2], keys[k, 1])
                if cubic:
                    _align(keys[k, 0], keys[k, 1])
                    _align(keys[k, 3], keys[k, 2])
            last[k] = i
        col = itab[k, 4]
        c = 4 if rotation else 3
        if cubic:
            # Catmull-Rom keys: Bessel velocities at keys i and i+1 (compression.cubic)
            h0 = key_times[i] - key_times[i0]
            h = key_times[i + 1] - key_times[i]
            h2 = key_times[i3] - key_times[i + 1]
            for m in range(c):
                a[m] = cubic_component(keys[k, 0, m], keys[k, 1, m], keys[k, 2, m],
                                       keys[k, 3, m], h0, h, h2, u)
        else:
            for m in range(c):
                a[m] = keys[k, 1, m] + (keys[k, 2, m] - keys[k, 1, m]) * u
        if rotation:
            n = np.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2] + a[3] * a[3])
            for m in range(4):
                out[col + m] = a[m] / n
        else:
            for m in range(3):
                out[col + m] = a[m]


@numba.njit(cache=True)
def pose_at(t, itab, sitab, sftab, key_seg, key_times, words, base, out):
    """One pose at clip time ``t`` into ``out`` (J * 10,) float64 (``base``: the rest with the
    constant tracks)."""
    out[:] = base
    a = np.empty(4)
    t_count = itab.shape[0]
    last = np.full(t_count, -1, dtype=np.int64)
    keys = np.zeros((t_count, 4, 4))
    _pose(t, itab, sitab, sftab, key_seg, key_times, words, _OTHERS, out, a, last, keys)


@numba.njit(cache=True)
def poses_at(times, itab, sitab, sftab, key_seg, key_times, words, base, out):
    """Poses at clip times (N,) into ``out`` (N, J * 10) float64."""
    a = np.empty(4)
    t_count = itab.shape[0]
    last = np.full(t_count, -1, dtype=np.int64)
    keys = np.zeros((t_count, 4, 4))
    for n in range(times.shape[0]):
        out[n, :] = base
        _pose(times[n], itab, sitab, sftab, key_seg, key_times, words, _OTHERS, out[n], a,
              last, keys)


@numba.njit(cache=True)
def pose_into(t, itab, sitab, sftab, key_seg, key_times, words, base, row, translation,
              rotation, scale, last, keys):
    """:func:`pose_at` into ``row``, then into a pose's own (J, 3), (J, 4), (J, 3) arrays in
    the same call (what ``CompressedClip.sample`` needs); ``last``, ``keys`` the caller's key
    cache (see :func:`_pose`), kept across calls: playback frame after frame in the same span
    decodes its keys once."""
    row[:] = base
    a = np.empty(4)
    _pose(t, itab, sitab, sftab, key_seg, key_times, words, _OTHERS, row, a, last, keys)
    for j in range(translation.shape[0]):
        o = j * 10
        for m in range(3):
            translation[j, m] = row[o + m]
            scale[j, m] = row[o + 7 + m]
        for m in range(4):
            rotation[j, m] = row[o + 3 + m]
