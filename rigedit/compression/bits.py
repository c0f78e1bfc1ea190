"""Bit streams: unsigned fields of 0 to 32 bits packed back to back, least significant bit
first, into little-endian 32-bit words (the layout docs/compression.md gives byte by byte)."""
from __future__ import annotations

import numpy as np

__all__ = ["MAX_FIELD_BITS", "pack", "words_of", "read_fields"]

MAX_FIELD_BITS = 32
#: Zero words after a stream's last field, so reading a field never runs past the end.
PAD_WORDS = 2


def pack(values, widths):
    """Pack fields into bytes.

    Parameters
    ----------
    values : (N,) int
        Each below ``2 ** widths[i]``.
    widths : (N,) int
        Bits of each field, 0..32.

    Returns
    -------
    stream : bytes
        ``ceil(total bits / 32)`` little-endian uint32 words (no padding).
    """
    values = np.asarray(values, dtype=np.uint64).reshape(-1)
    widths = np.asarray(widths, dtype=np.int64).reshape(-1)
    total = int(widths.sum())
    words = np.zeros((total + 31) // 32 + 1, dtype=np.uint64)
    start = np.concatenate([[0], np.cumsum(widths)[:-1]]).astype(np.int64)
    used = widths > 0
    values, widths, start = values[used], widths[used], start[used]
    word, shift = start >> 5, (start & 31).astype(np.uint64)
    low = (values << shift) & np.uint64(0xFFFFFFFF)
    np.bitwise_or.at(words, word, low)
    high = values >> (np.uint64(32) - shift)   # shift 0: a 64-bit shift by 32 gives 0 bits
    high = np.where(shift == 0, np.uint64(0), high)
    np.bitwise_or.at(words, word + 1, high)
    return words[: (total + 31) // 32].astype("<u4").tobytes()


def words_of(stream):
    """A stream's bytes as uint64 words (one per 32-bit word) with :data:`PAD_WORDS` zero words
    after, for :func:`read_fields`."""
    words = np.frombuffer(stream, dtype="<u4").astype(np.uint64)
    return np.concatenate([words, np.zeros(PAD_WORDS, dtype=np.uint64)])


def read_fields(words, start, widths):
    """Unsigned fields at bit offsets ``start`` (any shape) of ``widths`` bits (broadcast),
    read straight from the packed words; uint64 array of ``start``'s shape."""
    start = np.asarray(start, dtype=np.int64)
    word = start >> 5
    pair = words[word] | (words[word + 1] << np.uint64(32))
    mask = (np.uint64(1) << np.asarray(widths, dtype=np.uint64)) - np.uint64(1)
    return (pair >> (start & 31).astype(np.uint64)) & mask
