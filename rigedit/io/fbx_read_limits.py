"""FBX in: the bound on what a binary FBX file can make ufbx allocate, checked first.

ufbx allocates a binary FBX array by the length the file claims, before decoding it. The
Python binding exposes no memory limit (:mod:`rigedit.io.fbx_read_scene`), so the claims are
checked here, on the file's bytes, without decoding anything: every array's decoded size
must be one its stored bytes can produce (a deflate stream expands at most 1032 times, an
uncompressed array is exactly its bytes) and all of them together at most
:data:`MAX_DECODED_BYTES`. An ASCII file allocates by what it really contains, which the
file size bounds already (:data:`rigedit.io.paths.MAX_FILE_BYTES`).
"""
from __future__ import annotations

import struct

from ..errors import RigFileError

__all__ = ["check_claims", "MAX_DECODED_BYTES"]

#: The decoded arrays of one binary FBX file may take at most this many bytes.
MAX_DECODED_BYTES = 4 * 2**30
#: zlib's largest expansion of a deflate stream (258-byte matches in 2-bit codes).
_DEFLATE_RATIO = 1032
_MAGIC = b"Kaydara FBX Binary  \x00"
_ELEMENT = {"d": 8, "f": 4, "l": 8, "i": 4, "b": 1}
_SCALAR = {"Y": 2, "C": 1, "I": 4, "F": 4, "D": 8, "L": 8}


def _properties(data, p, count, end, path, state):
    """Walk ``count`` properties from ``p``; array claims checked into ``state``."""
    for _ in range(count):
        if p >= end:
            raise RigFileError(path, "expected a valid FBX file, got a record that runs past "
                                     "its end")
        kind = chr(data[p])
        p += 1
        if kind in _ELEMENT:
            length, encoding, stored = struct.unpack_from("<III", data, p)
            p += 12
            decoded = length * _ELEMENT[kind]
            if encoding == 0 and decoded != stored:
                raise RigFileError(path, f"expected an array of {stored} bytes to hold its "
                                         f"{length} values, got {decoded} bytes claimed")
            if encoding == 1 and decoded > _DEFLATE_RATIO * stored + 64:
                raise RigFileError(path, f"expected a compressed array that can expand to "
                                         f"its {length} values, got {stored} bytes")
            state[0] += decoded
            if state[0] > MAX_DECODED_BYTES:
                raise RigFileError(path, f"expected at most {MAX_DECODED_BYTES} bytes of "
                                         "arrays, got more claimed")
            p += stored
        elif kind in "SR":
            (length,) = struct.unpack_from("<I", data, p)
            p += 4 + length
        elif kind in _SCALAR:
            p += _SCALAR[kind]
        else:
            raise RigFileError(path, f"expected a valid FBX file, got a property of unknown "
                                     f"type {kind!r}")
    return p


def check_claims(data, path):
    """Refuse a binary FBX file whose arrays claim more than their bytes can hold.

    Parameters
    ----------
    data : bytes
        The whole file.
    path : Path
        For the messages.

    Raises
    ------
    RigFileError
        A record or property that runs past its end, an impossible array claim, or more than
        :data:`MAX_DECODED_BYTES` claimed in all. Files that are not binary FBX pass (ufbx
        reports what they are).
    """
    if not data.startswith(_MAGIC) or len(data) < 27:
        return
    version = struct.unpack_from("<I", data, 23)[0]
    wide = version >= 7500
    header = struct.Struct("<QQQB" if wide else "<IIIB")
    state = [0]
    stack = [len(data)]       # end offsets of the records being walked (no recursion)
    p = 27
    try:
        while stack:
            end = stack[-1]
            if p + header.size > end:
                p = stack.pop()
                continue
            record_end, count, _plen, name_len = header.unpack_from(data, p)
            if record_end == 0:                     # the null record closing a list
                p = stack.pop()
                continue
            if record_end > len(data):
                raise RigFileError(path, "expected a valid FBX file, got one that is cut "
                                         "short (a record ends past the end of the file)")
            if not p < record_end <= end:
                raise RigFileError(path, "expected a valid FBX file, got a record that runs "
                                         "past its parent")
            p = _properties(data, p + header.size + name_len, count, record_end, path, state)
            if p > record_end:
                raise RigFileError(path, "expected a valid FBX file, got properties that "
                                         "run past their record")
            stack.append(record_end)                # then its children, to record_end
    except struct.error:
        raise RigFileError(path, "expected a valid FBX file, got one that is cut short") \
            from None
