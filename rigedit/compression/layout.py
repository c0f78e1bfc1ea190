"""rigedit's compressed clip, byte by byte (docs/compression.md, "Binary layout").

A clip is one blob, little-endian; ``varint`` is LEB128 (7 bits a byte, low first):

====================  ======================================================================
name                  varint n, n bytes UTF-8
duration              float64 seconds (a looping clip wraps at it: exactly the source's)
flags                 uint8: bit 0 loop, bit 1 uniform frame times, bit 2 float64 times
frames                varint F (frame count of the time grid, >= 1)
time grid             uniform: float64 start, float64 period (frame i at start + i period);
                      else F float32 times (bit 2: F float64 times, for frames float32
                      cannot keep apart)
constant tracks       varint C, then C x (varint joint, uint8 channel, 3 or 4 float32)
animated tracks       varint A, then A track headers:
                      varint joint; uint8 channel (bits 0-1: 0 translation, 1 rotation,
                      2 scale) | rotation mode << 2 (0-3 fixed dropped component, 4 per key)
                      | 32 when segmented (its values per 16-frame segment)
                      | 64 when its keys are joined by the Catmull-Rom cubic
                      (compression/cubic.py) instead of LERP / NLERP;
                      varint K (keys, 2..F); uint8 D (bits per key-frame step, 0: every
                      frame is a key, 255: a bit per frame); per-key rotation: uint8 B (bits of all three
                      components); fixed rotation: 3 uint8 bits, 3 uint16 lo, 3 uint16
                      extent (on [-1, 1]: lo16 * 2 / 65535 - 1, ext16 * 2 / 65535);
                      translation, scale: 3 uint8 bits, 3 float32 lo, 3 float32 extent
bit stream            varint n words, n uint32 words: first every animated track's key
                      frames (D = 255: F bits, 1 where a frame is a key; else K - 1 steps
                      of D bits each, the first key frame 0), then every
                      animated track's values: a segmented track's 63-bit header per
                      segment holding a key (3 x 8-bit a, 3 x 8-bit b, 3 x 5-bit bits: the
                      range lo + a ext / 255, (b - a) ext / 255), then its K keys, each
                      [2 bits dropped component, per-key rotations only] + 3 components
                      in their (segment's) bits
====================  ======================================================================

A component of b bits is ``lo + code * extent / (2^b - 1)``, of 0 bits ``lo + extent / 2``.
Every count read is checked against the blob's size before anything is allocated for it.
"""
from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np

from ..animation.clip_names import check_clip_name
from .bits import MAX_FIELD_BITS, pack
from .quantise import (PER_KEY, SEGMENT, SEGMENT_HEADER_BITS, VectorCode, unit_range_codes,
                       unit_range_values)

__all__ = ["CHANNEL_CODES", "EncodedTrack", "ClipLayout", "write_clip", "read_clip",
           "LayoutError", "ByteReader", "varint"]

CHANNEL_CODES = {"translation": 0, "rotation": 1, "scale": 2}
CHANNEL_NAMES = {v: k for k, v in CHANNEL_CODES.items()}
WIDTH = {"translation": 3, "rotation": 4, "scale": 3}


class LayoutError(ValueError):
    """A blob that is not a well-formed compressed clip (the message says what is wrong)."""


@dataclass
class EncodedTrack:
    """One stored track: ``value`` (C,) float32 when constant; else ``keys`` (K,) frame
    indices, ``mode`` (rotation: 0-3 or PER_KEY; 0 for vectors), ``code`` and, per-key
    rotations, ``dropped`` (K,)."""

    joint: int
    channel: str
    value: np.ndarray = None
    keys: np.ndarray = None
    mode: int = 0
    code: VectorCode = None
    dropped: np.ndarray = None
    segments: object = None     # SegmentCode when segmented (writing), the used segments'
    #                             (index, a, b, bits) arrays when read
    cubic: bool = False         # keys joined by the Catmull-Rom cubic (.cubic), not LERP


@dataclass
class ClipLayout:
    """A clip as the blob holds it (see the module notes)."""

    name: str
    duration: float
    loop: bool
    times: np.ndarray          # (F,) float64 as decoded from the grid
    uniform: tuple             # (start, period) or None
    constant: list             # EncodedTrack
    animated: list             # EncodedTrack
    wide: bool = False         # non-uniform times stored as float64 (float32 merges some)


#: Flag bit of a clip whose non-uniform frame times are stored as float64.
WIDE_TIMES = 4
#: Largest frame time or duration a blob may hold, seconds (about 30 years): far beyond any
#: clip, and small enough that a pose's time arithmetic stays finite and exact to the key.
MAX_SECONDS = 1e9


def grid_times(count, uniform, times=None, wide=False):
    """The decoded frame times (F,) float64 of a grid (``wide``: float64 times, else float32)."""
    if uniform is not None:
        start, period = uniform
        return start + np.arange(count) * period
    return np.asarray(times, dtype=np.float64 if wide else np.float32).astype(np.float64)


def varint(n):
    """``n`` >= 0 as LEB128 bytes."""
    n = int(n)
    out = bytearray()
    while True:
        byte = n & 0x7F
        n >>= 7
        if n:
            out.append(byte | 0x80)
        else:
            out.append(byte)
            return bytes(out)


#: Bit of a track's code byte: its values are quantised per segment of frames.
SEGMENTED = 32
#: Bit of a track's code byte: its keys are joined by the Catmull-Rom cubic.
CUBIC = 64
_HEADER_AT = np.array([0, 8, 16, 24, 32, 40, 48, 53, 58])
_HEADER_WIDTHS = np.array([8, 8, 8, 8, 8, 8, 5, 5, 5])

#: Key-frame code D meaning "a bit per frame" (1: a key) instead of steps.
MASK = 255


def key_code(keys, count):
    """How a track's key frames are stored: ``(D, bits)``: D = 0 every frame is a key (no
    bits), :data:`MASK` one bit per frame, else K - 1 steps of D bits; the cheaper of the last
    two."""
    keys = np.asarray(keys, dtype=np.int64)
    if len(keys) == count:
        return 0, 0
    dbits = max(int(np.diff(keys).max()).bit_length(), 1)
    steps = (len(keys) - 1) * dbits
    return (MASK, count) if count < steps else (dbits, steps)


def write_clip(layout):
    """The blob of a :class:`ClipLayout`, bytes."""
    out = bytearray()
    name = layout.name.encode("utf-8")
    out += varint(len(name)) + name
    wide = bool(layout.wide) and not layout.uniform
    out += struct.pack("<dB", layout.duration, int(layout.loop) | (2 if layout.uniform else 0)
                       | (WIDE_TIMES if wide else 0))
    out += varint(len(layout.times))
    if layout.uniform:
        out += struct.pack("<dd", *layout.uniform)
    else:
        out += np.asarray(layout.times, dtype="<f8" if wide else "<f4").tobytes()
    out += varint(len(layout.constant))
    for tr in layout.constant:
        out += varint(tr.joint) + bytes([CHANNEL_CODES[tr.channel]])
        out += np.asarray(tr.value, dtype="<f4").tobytes()
    out += varint(len(layout.animated))
    fields, widths = [], []
    count = len(layout.times)
    for tr in layout.animated:
        keys = np.asarray(tr.keys, dtype=np.int64)
        steps = np.diff(keys)
        dbits = key_code(keys, count)[0]
        segmented = SEGMENTED if tr.segments is not None else 0
        cubic = CUBIC if tr.cubic else 0
        out += varint(tr.joint) + bytes([CHANNEL_CODES[tr.channel] | (tr.mode << 2) | segmented
                                         | cubic])
        out += varint(len(keys)) + bytes([dbits])
        if tr.mode == PER_KEY:
            out += bytes([int(tr.code.bits[0])])
        else:
            out += bytes(int(b) for b in tr.code.bits)
            if tr.channel == "rotation":
                lo16, ext16 = unit_range_codes(tr.code.lo, tr.code.ext)
                out += lo16.astype("<u2").tobytes() + ext16.astype("<u2").tobytes()
            else:
                out += np.asarray(tr.code.lo, dtype="<f4").tobytes()
                out += np.asarray(tr.code.ext, dtype="<f4").tobytes()
        if dbits == MASK:
            mask = np.zeros(count, dtype=np.uint64)
            mask[keys] = 1
            fields.append(mask)
            widths.append(np.ones(count, dtype=np.int64))
        elif dbits:
            fields.append(steps)
            widths.append(np.full(len(steps), dbits))
    for tr in layout.animated:
        k = len(tr.keys)
        bits = np.asarray(tr.code.bits, dtype=np.int64)
        if tr.segments is not None:
            seg = tr.segments
            which = np.asarray(tr.keys) // SEGMENT
            used = np.unique(which)
            head = np.column_stack([seg.a[used], seg.b[used], seg.bits[used]])
            fields.append(head.astype(np.uint64).reshape(-1))
            widths.append(np.tile(np.r_[8, 8, 8, 8, 8, 8, 5, 5, 5], len(used)))
            fields.append(np.asarray(tr.code.codes, dtype=np.uint64).reshape(-1))
            widths.append(np.asarray(seg.bits, dtype=np.int64)[which].reshape(-1))
            continue
        if tr.mode == PER_KEY:
            per = np.column_stack([np.asarray(tr.dropped, dtype=np.uint64), tr.code.codes])
            w = np.r_[2, bits]
        else:
            per, w = tr.code.codes, bits
        fields.append(np.asarray(per, dtype=np.uint64).reshape(-1))
        widths.append(np.tile(w, k))
    stream = pack(np.concatenate(fields) if fields else np.zeros(0),
                  np.concatenate(widths) if widths else np.zeros(0))
    out += varint(len(stream) // 4) + stream
    return bytes(out)


class ByteReader:
    """Reads a blob front to back; every read checked against its end."""

    def __init__(self, blob):
        self.blob, self.at = memoryview(blob), 0

    def take(self, n, what):
        if n < 0 or self.at + n > len(self.blob):
            raise LayoutError(f"truncated clip data: {what} needs {n} bytes at byte "
                              f"{self.at}, {len(self.blob) - self.at} left")
        part = self.blob[self.at:self.at + n]
        self.at += n
        return part

    def varint(self, what, limit):
        n, shift = 0, 0
        while True:
            byte = self.take(1, what)[0]
            n |= (byte & 0x7F) << shift
            shift += 7
            if not byte & 0x80:
                break
            if shift > 63:
                raise LayoutError(f"{what}: a number longer than 9 bytes")
        if n > limit:
            raise LayoutError(f"{what}: {n}, expected at most {limit}")
        return n

    def u8(self, what):
        return self.take(1, what)[0]

    def floats(self, n, what, dtype="<f4"):
        size = np.dtype(dtype).itemsize
        with np.errstate(invalid="ignore", over="ignore"):   # a NaN is refused by the caller
            return np.frombuffer(self.take(n * size, what), dtype=dtype).astype(np.float64)


def read_clip(blob, num_joints):
    """Parse a blob into a :class:`ClipLayout` and its bit stream.

    Returns
    -------
    layout : ClipLayout
        Animated tracks' ``code.codes`` are None (the values stay in the stream), their
        ``keys`` decoded.
    stream : bytes
    value_offsets : list of int
        Bit offset of each animated track's first key in the stream.

    Raises
    ------
    LayoutError
        Truncated data, a count beyond what the blob can hold, a joint index beyond
        ``num_joints``, unknown codes, key steps that do not fit the frames.
    """
    r = ByteReader(blob)
    size = len(blob)
    raw = bytes(r.take(r.varint("clip name length", size), "clip name"))
    try:   # not UTF-8, or a name a Clip would refuse (a control character, a slash)
        name = check_clip_name(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise LayoutError(f"clip name {raw[:40]!r}: expected UTF-8") from None
    except ValueError as exc:
        raise LayoutError(str(exc)) from None
    duration, flags = struct.unpack("<dB", r.take(9, "duration and flags"))
    if not 0 <= duration <= MAX_SECONDS:   # also refuses NaN
        raise LayoutError(f"clip {name!r}: duration {duration}, expected 0 to {MAX_SECONDS:g} "
                          "seconds")
    count = r.varint("frame count", size * 8)
    if count < 1:
        raise LayoutError(f"clip {name!r}: no frames")
    if flags & 2:
        start, period = struct.unpack("<dd", r.take(16, "frame grid"))
        end = start + (count - 1) * period if abs(period) <= MAX_SECONDS else np.inf
        if not (abs(start) <= MAX_SECONDS and abs(end) <= MAX_SECONDS and period >= 0):
            raise LayoutError(f"clip {name!r}: frame grid {start}, {period}: expected times "
                              f"within {MAX_SECONDS:g} seconds")
        uniform, times = (start, period), grid_times(count, (start, period))
    else:
        wide = bool(flags & WIDE_TIMES)
        uniform, times = None, r.floats(count, "frame times", "<f8" if wide else "<f4")
    if not np.all(np.abs(times) <= MAX_SECONDS) or np.any(np.diff(times) <= 0):
        raise LayoutError(f"clip {name!r}: frame times not finite, increasing and within "
                          f"{MAX_SECONDS:g} seconds")
    constant = []
    for _ in range(r.varint("constant track count", size)):
        joint = r.varint("joint index", num_joints - 1)
        channel = CHANNEL_NAMES.get(r.u8("channel"))
        if channel is None:
            raise LayoutError(f"clip {name!r}: unknown channel code")
        value = r.floats(WIDTH[channel], "constant value")
        if not np.all(np.isfinite(value)) or (channel == "rotation"
                                              and np.linalg.norm(value) < 1e-6):
            raise LayoutError(f"clip {name!r}: a constant {channel} is not a finite value")
        constant.append(EncodedTrack(joint, channel, value=value))
    animated, dbits_all = [], []
    for _ in range(r.varint("animated track count", size)):
        joint = r.varint("joint index", num_joints - 1)
        code = r.u8("channel")
        channel, mode, segmented = CHANNEL_NAMES.get(code & 3), (code >> 2) & 7, code & SEGMENTED
        if (channel is None or mode > PER_KEY or (channel != "rotation" and mode)
                or code > 127 or (segmented and mode == PER_KEY)):
            raise LayoutError(f"clip {name!r}: unknown track code {code}")
        keys = r.varint("key count", count)
        dbits = r.u8("key step bits")
        if keys < 2 or count < 2 or (32 < dbits < MASK) or (dbits == 0 and keys != count):
            raise LayoutError(f"clip {name!r}: {keys} keys of {count} frames, step bits "
                              f"{dbits}")
        if mode == PER_KEY:
            bits = np.full(3, r.u8("component bits"))
            lo = np.full(3, -np.sqrt(0.5), dtype=np.float32)
            ext = np.full(3, 2 * np.sqrt(0.5), dtype=np.float32)
        else:
            bits = np.frombuffer(r.take(3, "component bits"), dtype=np.uint8).astype(np.int64)
            if channel == "rotation":
                lo, ext = unit_range_values(r.floats(3, "range low", "<u2"),
                                            r.floats(3, "range extent", "<u2"))
            else:
                lo = r.floats(3, "range low").astype(np.float32)
                ext = r.floats(3, "range extent").astype(np.float32)
        if np.any(bits > MAX_FIELD_BITS) or not (np.all(np.isfinite(lo))
                                                 and np.all(np.isfinite(ext))):
            raise LayoutError(f"clip {name!r}: a track's range or bits are not valid")
        animated.append(EncodedTrack(joint, channel, keys=keys, mode=mode,
                                     code=VectorCode(lo, ext, np.asarray(bits), None),
                                     segments=True if segmented else None,
                                     cubic=bool(code & CUBIC)))
        dbits_all.append(dbits)
    words = r.varint("bit stream length", size // 4)
    stream = bytes(r.take(words * 4, "bit stream"))
    if r.at != size:
        raise LayoutError(f"clip {name!r}: {size - r.at} bytes after the bit stream")
    layout = ClipLayout(name, float(duration), bool(flags & 1), times, uniform, constant,
                        animated, uniform is None and bool(flags & WIDE_TIMES))
    return layout, stream, _key_frames(layout, stream, dbits_all)


def _key_frames(layout, stream, dbits_all):
    """Decode every animated track's key frames into ``track.keys`` and return each track's
    value bit offset; checks the stream holds what the headers claim."""
    from .bits import read_fields, words_of
    count = len(layout.times)
    need = 0
    for tr, dbits in zip(layout.animated, dbits_all):
        need += count if dbits == MASK else (tr.keys - 1) * dbits
    total = len(stream) * 8
    if need > total:
        raise LayoutError(f"clip {layout.name!r}: the bit stream holds {total} bits, its key "
                          f"frames need {need}")
    words = words_of(stream)
    at = 0
    for tr, dbits in zip(layout.animated, dbits_all):
        k = tr.keys
        if dbits == 0:
            tr.keys = np.arange(count)
            continue
        if dbits == MASK:
            keys = np.flatnonzero(read_fields(words, at + np.arange(count), 1))
            at += count
            steps = np.diff(keys)
            if len(keys) != k or keys[0] != 0:
                raise LayoutError(f"clip {layout.name!r}: a track's key mask holds "
                                  f"{len(keys)} keys, its header {k}")
        else:
            steps = read_fields(words, at + np.arange(k - 1) * dbits, dbits).astype(np.int64)
            at += (k - 1) * dbits
            keys = np.concatenate([[0], np.cumsum(steps)])
        if np.any(steps <= 0) or keys[-1] != count - 1:
            raise LayoutError(f"clip {layout.name!r}: key frames of a track do not run from "
                              f"the first frame to the last")
        tr.keys = keys
    return _value_offsets(layout, words, need, total)


def _value_offsets(layout, words, at, total):
    """Each animated track's bit offset of its first key; reads a segmented track's segment
    headers into ``track.segments`` = (used segment indices, a, b, bits), each checked."""
    from .bits import read_fields
    offsets = []
    for tr in layout.animated:
        if tr.segments is not None:
            which = tr.keys // SEGMENT
            used = np.unique(which)
            if at + len(used) * SEGMENT_HEADER_BITS > total:
                raise LayoutError(f"clip {layout.name!r}: the bit stream ends in a track's "
                                  "segment headers")
            pos = at + (np.arange(len(used)) * SEGMENT_HEADER_BITS)[:, None] + _HEADER_AT
            head = read_fields(words, pos, _HEADER_WIDTHS).astype(np.int64)
            a, b, bits = head[:, 0:3], head[:, 3:6], head[:, 6:9]
            if np.any(b < a):
                raise LayoutError(f"clip {layout.name!r}: a segment's range ends are reversed")
            tr.segments = (used, a, b, bits)
            at += len(used) * SEGMENT_HEADER_BITS
            offsets.append(at)
            at += int(bits[np.searchsorted(used, which)].sum())
        else:
            offsets.append(at)
            at += len(tr.keys) * (int(np.sum(tr.code.bits)) + (2 if tr.mode == PER_KEY else 0))
        if at > total:
            raise LayoutError(f"clip {layout.name!r}: the bit stream holds {total} bits, its "
                              f"tracks need at least {at}")
    return offsets
