"""The decoder's compiled kernels (numba): one pose, or a batch of poses, straight from the
packed words, one loop over the animated tracks (a binary search in the track's key times,
two keys' fields read, dequantised, the dropped component rebuilt, LERP / NLERP).

Imported only by :func:`rigedit.compression.codec.kernels` (which imports numba through
this module, once, on first use, and caches the compiled code on disk with
``cache=True``); :class:`~rigedit.compression.codec.ClipDecoder`'s numpy path is the
reference and the fallback (``RIGEDIT_NO_NUMBA=1``). The tables are built by the decoder:

``itab`` (T, 6) int64 per animated track: key start, key count, lead bits (2 for per-key
rotations), is-rotation, target column (joint * 10 + first column), fixed dropped component;
``sitab`` (S, 9) int64 per segment of stored keys (a whole track when not segmented): bit
offset of its first key, that key's index in its track, stride, the three fields' offsets,
the three fields' bits; ``sftab`` (S, 6) float64: lo (3), scale (3); ``key_seg`` (K,) each
key's segment.
"""
from __future__ import annotations

import numba
import numpy as np

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
def _pose(t, itab, sitab, sftab, key_seg, key_times, words, others, out, a, b, last, qa, qb):
    """One pose into ``out``; ``last`` (T,) the key each track decoded last and ``qa``, ``qb``
    (T, 4) its two keys, reused when ``t`` falls between the same keys (a batch of times)."""
    for k in range(itab.shape[0]):
        lo = itab[k, 0]
        hi = lo + itab[k, 1] - 1
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
        if last[k] != i:
            _decode_key(words, itab, sitab, sftab, key_seg, k, i, others, qa[k])
            _decode_key(words, itab, sitab, sftab, key_seg, k, i + 1, others, qb[k])
            last[k] = i
        for m in range(4):
            a[m] = qa[k, m]
            b[m] = qb[k, m]
        col = itab[k, 4]
        if itab[k, 3] == 0:
            for m in range(3):
                out[col + m] = a[m] + (b[m] - a[m]) * u
        else:
            d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
            s = -1.0 if d < 0 else 1.0
            n = 0.0
            for m in range(4):
                a[m] = a[m] + (s * b[m] - a[m]) * u
                n += a[m] * a[m]
            n = np.sqrt(n)
            for m in range(4):
                out[col + m] = a[m] / n


@numba.njit(cache=True)
def pose_at(t, itab, sitab, sftab, key_seg, key_times, words, base, out):
    """One pose at clip time ``t`` into ``out`` (J * 10,) float64 (``base``: the rest with the
    constant tracks)."""
    out[:] = base
    a = np.empty(4)
    b = np.empty(4)
    t_count = itab.shape[0]
    last = np.full(t_count, -1, dtype=np.int64)
    qa = np.zeros((t_count, 4))
    qb = np.zeros((t_count, 4))
    _pose(t, itab, sitab, sftab, key_seg, key_times, words, _OTHERS, out, a, b, last, qa, qb)


@numba.njit(cache=True)
def poses_at(times, itab, sitab, sftab, key_seg, key_times, words, base, out):
    """Poses at clip times (N,) into ``out`` (N, J * 10) float64."""
    a = np.empty(4)
    b = np.empty(4)
    t_count = itab.shape[0]
    last = np.full(t_count, -1, dtype=np.int64)
    qa = np.zeros((t_count, 4))
    qb = np.zeros((t_count, 4))
    for n in range(times.shape[0]):
        out[n, :] = base
        _pose(times[n], itab, sitab, sftab, key_seg, key_times, words, _OTHERS, out[n], a, b,
              last, qa, qb)


@numba.njit(cache=True)
def pose_into(t, itab, sitab, sftab, key_seg, key_times, words, base, row, translation,
              rotation, scale, last, qa, qb):
    """:func:`pose_at` into ``row``, then into a pose's own (J, 3), (J, 4), (J, 3) arrays in
    the same call (what ``CompressedClip.sample`` needs); ``last``, ``qa``, ``qb`` the
    caller's key cache (see :func:`_pose`), kept across calls: playback frame after frame
    between the same two keys decodes them once."""
    row[:] = base
    a = np.empty(4)
    b = np.empty(4)
    _pose(t, itab, sitab, sftab, key_seg, key_times, words, _OTHERS, row, a, b, last, qa, qb)
    for j in range(translation.shape[0]):
        o = j * 10
        for m in range(3):
            translation[j, m] = row[o + m]
            scale[j, m] = row[o + 7 + m]
        for m in range(4):
            rotation[j, m] = row[o + 3 + m]
