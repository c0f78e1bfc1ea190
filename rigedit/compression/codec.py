"""The decoder: whole poses at any time straight from the bit stream.

What is decoded once, when a clip is opened: the headers and each track's key frames (times,
a few bytes per key); the values stay packed. A pose at time ``t`` is then, for all animated
tracks at once: one ``searchsorted`` over every track's key times (each track's times shifted
by its own offset so one sorted array holds them all), the two neighbouring keys' fields read
from the 32-bit words (two words per field, a shift and a mask; four keys for a track of
Catmull-Rom keys), dequantised, the dropped rotation component rebuilt, LERP / NLERP on the
shortest path or the cubic (:mod:`.cubic`), and a scatter into the pose array. A batch of N
times runs the same operations on (N, tracks) arrays.
"""
from __future__ import annotations

import numpy as np

from .bits import read_fields, words_of
from .cubic import hermite_cr
from .frames import COLUMNS
from .kernels import load, loaded
from .quantise import OTHERS, PER_KEY, SEGMENT, segment_range

__all__ = ["ClipDecoder", "kernels", "kernels_loaded"]

def kernels_loaded():
    """True once :func:`kernels` has imported the compiled kernels."""
    return loaded("codec_kernels")


def kernels():
    """The compiled decode kernels (:mod:`.codec_kernels`), imported and compiled (or loaded
    from numba's disk cache) on the first call; None when numba is missing or
    ``RIGEDIT_NO_NUMBA=1``."""
    return load("codec_kernels")


class ClipDecoder:
    """Samples one compressed clip.

    Parameters
    ----------
    layout : ClipLayout
        With decoded key frames (:func:`~rigedit.compression.layout.read_clip`).
    stream : bytes
    offsets : list of int
        Bit offset of each animated track's values.
    rest : (J, 10) float64
        The skeleton's rest pose row (:meth:`Pose.as_array`): what tracks not stored hold.
    """

    def __init__(self, layout, stream, offsets, rest):
        self.layout = layout
        self.words = words_of(stream)
        base = np.array(rest, dtype=np.float64)
        for tr in layout.constant:
            value = np.asarray(tr.value, dtype=np.float64)
            if tr.channel == "rotation":
                value = value / np.linalg.norm(value)
            base[tr.joint, COLUMNS[tr.channel]] = value
        self.base = base.reshape(-1)
        self.num_joints = len(rest)
        tracks = layout.animated
        self.count = len(tracks)
        times = layout.times
        lengths = np.array([len(tr.keys) for tr in tracks], dtype=np.int64)
        self.start = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
        self.last = self.start + lengths - 2          # the last segment's first key
        span = float(times[-1] - times[0]) + 1.0 if len(times) else 1.0
        self.shift = np.arange(self.count) * span
        keys = [times[tr.keys] for tr in tracks]
        self.key_times = np.concatenate(keys) if keys else np.zeros(0)
        self.shifted = self.key_times + np.repeat(self.shift, lengths)
        per_key = np.array([tr.mode == PER_KEY for tr in tracks], dtype=bool)
        lead = np.where(per_key, 2, 0).astype(np.int64)
        self._segment_tables(tracks, offsets, lead)
        self.per_key = per_key
        self.fixed = np.array([0 if tr.mode == PER_KEY else tr.mode for tr in tracks],
                              dtype=np.int64)
        rot = np.array([tr.channel == "rotation" for tr in tracks], dtype=bool)
        self.rot = np.flatnonzero(rot)
        self.vec = np.flatnonzero(~rot)
        joint = np.array([tr.joint for tr in tracks], dtype=np.int64)
        first = np.array([COLUMNS[tr.channel].start for tr in tracks], dtype=np.int64)
        self.vec_target = (joint[self.vec] * 10 + first[self.vec])[:, None] + np.arange(3)
        self.rot_target = (joint[self.rot] * 10 + 3)[:, None] + np.arange(4)
        self.rot_per_key = per_key[self.rot]
        cubic = np.array([tr.cubic for tr in tracks], dtype=bool)
        self.vec_cubic, self.rot_cubic = cubic[self.vec], cubic[self.rot]
        self.itab = np.column_stack([
            self.start, lengths, lead, rot.astype(np.int64), joint * 10 + first,
            self.fixed, cubic.astype(np.int64)]).astype(np.int64) if self.count else \
            np.zeros((0, 7), dtype=np.int64)
        self.sitab = np.ascontiguousarray(np.column_stack([
            self.seg_offset, self.seg_first, self.seg_stride, self.seg_field,
            self.seg_bits]).astype(np.int64))
        self.sftab = np.ascontiguousarray(np.column_stack([self.seg_lo, self.seg_scale]))
        self.compiled = None
        # the compiled single-pose path's key cache: the span each track decoded last, and
        # its keys i-1 .. i+2 (keys never change, so it never goes stale)
        self._cache = (np.full(self.count, -1, dtype=np.int64), np.zeros((self.count, 4, 4)))

    def _segment_tables(self, tracks, offsets, lead):
        """Per segment of stored keys (a whole track when it is not segmented): bit offset of
        its first key, that key's index in the track, the stride, the three fields' offsets
        and bits, lo and scale; ``key_seg``: each key's segment. Decoded once, at opening."""
        cols = {k: [] for k in ("offset", "first", "stride", "bits", "lo", "ext")}
        key_seg, total = [], 0
        for i, tr in enumerate(tracks):
            lo = np.asarray(tr.code.lo, dtype=np.float64)
            ext = np.asarray(tr.code.ext, dtype=np.float64)
            k = len(tr.keys)
            if tr.segments is None:
                s_lo, s_ext = lo[None], ext[None]
                s_bits = np.asarray(tr.code.bits, dtype=np.int64)[None]
                index = np.zeros(k, dtype=np.int64)
            else:
                used, a, b, s_bits = tr.segments
                s_lo, s_ext = segment_range(lo, ext, a, b)
                index = np.searchsorted(used, tr.keys // SEGMENT)
            counts = np.bincount(index, minlength=len(s_bits))
            stride = s_bits.sum(axis=1) + lead[i]
            cols["offset"].append(offsets[i] + np.concatenate([[0], np.cumsum(counts * stride)
                                                               [:-1]]))
            cols["first"].append(np.concatenate([[0], np.cumsum(counts)[:-1]]))
            cols["stride"].append(stride)
            cols["bits"].append(s_bits)
            cols["lo"].append(s_lo)
            cols["ext"].append(s_ext)
            key_seg.append(index + total)
            total += len(s_bits)
        cat = {k: (np.concatenate(v) if v else np.zeros((0, 3) if k in ("bits", "lo", "ext")
                                                       else 0)) for k, v in cols.items()}
        bits = cat["bits"].astype(np.int64).reshape(-1, 3)
        self.seg_offset = cat["offset"].astype(np.int64)
        self.seg_first = cat["first"].astype(np.int64)
        self.seg_stride = cat["stride"].astype(np.int64)
        self.seg_bits = bits
        seg_lead = np.repeat(lead, [len(b) for b in cols["bits"]]) if tracks else \
            np.zeros(0, dtype=np.int64)
        self.seg_field = seg_lead[:, None] + np.concatenate(
            [np.zeros((len(bits), 1), np.int64), np.cumsum(bits, axis=1)[:, :2]], axis=1)
        levels = (np.left_shift(1, bits) - 1).astype(np.float64)
        lo, ext = cat["lo"].reshape(-1, 3), cat["ext"].reshape(-1, 3)
        self.seg_scale = np.where(levels > 0, ext / np.maximum(levels, 1), 0.0)
        self.seg_lo = np.where(levels > 0, lo, lo + ext / 2)
        self.key_seg = np.concatenate(key_seg).astype(np.int64) if key_seg else \
            np.zeros(0, dtype=np.int64)

    def _fields(self, global_key, track):
        """Bit offset (...) of keys given by global index and their track (broadcast), the
        three components (..., 3) and the segment (...)."""
        seg = self.key_seg[global_key]
        local = global_key - self.start[track]
        at = self.seg_offset[seg] + (local - self.seg_first[seg]) * self.seg_stride[seg]
        codes = read_fields(self.words, at[..., None] + self.seg_field[seg], self.seg_bits[seg])
        return at, self.seg_lo[seg] + codes * self.seg_scale[seg]

    def use_kernels(self, on=True):
        """Decode with the compiled kernels (when numba is there) or with numpy."""
        self.compiled = kernels() if on else None
        return self.compiled is not None

    def pose_arrays(self, t, row, translation, rotation, scale):
        """One pose at clip time ``t`` into a pose's arrays ((J, 3), (J, 4), (J, 3), float64,
        C-contiguous); ``row`` (J * 10,) a scratch buffer."""
        if self.compiled is not None:
            self.compiled.pose_into(float(t), self.itab, self.sitab, self.sftab, self.key_seg,
                                    self.key_times, self.words, self.base, row, translation,
                                    rotation, scale, *self._cache)
            return
        grid = self.pose_into(t, row).reshape(-1, 10)
        translation[:], rotation[:], scale[:] = grid[:, :3], grid[:, 3:7], grid[:, 7:]

    def pose_into(self, t, out):
        """One pose at clip time ``t`` into ``out`` (J * 10,) float64."""
        if self.compiled is not None:
            self.compiled.pose_at(float(t), self.itab, self.sitab, self.sftab, self.key_seg,
                                  self.key_times, self.words, self.base, out)
        else:
            out[:] = self.local_many(np.array([float(t)])).reshape(-1)
        return out

    def _interpolate(self, t):
        """Values of every animated track at clip times ``t`` (N,): vectors (N, Tv, 3),
        rotations (N, Tr, 4)."""
        n = len(t)
        pos = np.searchsorted(self.shifted, t[:, None] + self.shift[None, :], side="right") - 1
        i = np.clip(pos, self.start, self.last)                       # (N, T)
        # keys i-1 .. i+2 of each track, clamped to the track (the cubic's neighbours; a
        # clamped one gives the end key's secant)
        key = np.clip(i[..., None] + np.arange(-1, 3), self.start[:, None],
                      (self.last + 1)[:, None])                       # (N, T, 4)
        kt = self.key_times[key]
        u = np.clip((t[:, None] - kt[..., 1]) / (kt[..., 2] - kt[..., 1]), 0.0, 1.0)
        at, comps = self._fields(key, np.arange(self.count)[:, None])  # (N, T, 4, 3)
        vec = comps[:, self.vec]
        a, b = vec[:, :, 1], vec[:, :, 2]
        vectors = a + (b - a) * u[:, self.vec, None]
        if self.vec_cubic.any():
            c = self.vec_cubic
            kv = kt[:, self.vec[c]]
            vectors[:, c] = hermite_cr(*(kv[..., m] for m in range(4)),
                                       *(vec[:, c, m] for m in range(4)), t[:, None], False)
        three = comps[:, self.rot]                                    # (N, Tr, 4, 3)
        dropped = np.broadcast_to(self.fixed[self.rot][:, None], (n, len(self.rot), 4))
        if self.rot_per_key.any():
            idx = read_fields(self.words, at[:, self.rot], 2).astype(np.int64)
            dropped = np.where(self.rot_per_key[:, None], idx, dropped)
        w = np.sqrt(np.maximum(1.0 - np.sum(three * three, axis=-1), 0.0))
        q = np.empty(three.shape[:-1] + (4,))
        np.put_along_axis(q, dropped[..., None], w[..., None], axis=-1)
        np.put_along_axis(q, OTHERS[dropped], three, axis=-1)
        qa, qb = q[:, :, 1], q[:, :, 2]
        qb = np.where(np.sum(qa * qb, axis=-1, keepdims=True) < 0, -qb, qb)
        rq = qa + (qb - qa) * u[:, self.rot, None]
        rq /= np.linalg.norm(rq, axis=-1, keepdims=True)
        if self.rot_cubic.any():
            c = self.rot_cubic
            kr = kt[:, self.rot[c]]
            rq[:, c] = hermite_cr(*(kr[..., m] for m in range(4)),
                                  *(q[:, c, m] for m in range(4)), t[:, None], True)
        return vectors, rq

    def local_many(self, t):
        """Local poses (N, J, 10) at clip times ``t`` (N,) (already wrapped or clamped)."""
        t = np.asarray(t, dtype=np.float64).reshape(-1)
        if self.compiled is not None:
            out = np.empty((len(t), len(self.base)))
            self.compiled.poses_at(t, self.itab, self.sitab, self.sftab, self.key_seg,
                                   self.key_times, self.words, self.base, out)
            return out.reshape(len(t), self.num_joints, 10)
        out = np.repeat(self.base[None], len(t), axis=0)
        if self.count:
            vectors, rotations = self._interpolate(t)
            out[:, self.vec_target] = vectors
            out[:, self.rot_target] = rotations
        return out.reshape(len(t), self.num_joints, 10)

    def keys(self, index):
        """Key times (K,) and decoded values (K, C) of animated track ``index``."""
        tr = self.layout.animated[index]
        k = len(tr.keys)
        at, comps = self._fields(self.start[index] + np.arange(k), index)
        times = self.key_times[self.start[index]:self.start[index] + k]
        if tr.channel != "rotation":
            return times, comps
        dropped = (read_fields(self.words, at, 2).astype(np.int64) if self.per_key[index]
                   else np.full(k, self.fixed[index]))
        from .quantise import rotation_from_three
        return times, rotation_from_three(comps, dropped)
