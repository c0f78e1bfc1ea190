"""Binary FBX encoding: a tree of node records -> the bytes of a ``.fbx`` file.

Only the container, not what the nodes mean (that is :mod:`rigedit.io.fbx_document`). The layout,
as documented by Blender's io_scene_fbx (its binary specification of 2013) and the ufbx
project, for versions below 7500 (32-bit offsets):

- header: ``b"Kaydara FBX Binary  \\x00"``, ``b"\\x1a\\x00"``, the version (uint32);
- a node record: end offset (uint32, from the start of the file), number of properties
  (uint32), byte length of the property list (uint32), name length (uint8), the name, the
  properties, the child records, and a 13-byte null record after the children (also after a
  node with neither properties nor children, unless it is the last of its list); the top level
  ends with a null record too;
- a property: a type code and its data, little-endian: ``C`` bool (1 byte), ``Y`` int16,
  ``I`` int32, ``L`` int64, ``F`` float32, ``D`` float64; ``S`` string and ``R`` raw bytes
  (uint32 length, then the bytes); arrays ``b i l f d`` (bool, int32, int64, float32,
  float64: uint32 count, uint32 encoding, 0 raw or 1 zlib, uint32 byte length, the data);
- the footer: a 16-byte id, four zero bytes, zero padding to a multiple of 16 (16 when already
  aligned), the version again, 120 zero bytes and a 16-byte closing id.

The FBX SDK checks the file id of the header against the ``CreationTime`` string (a hash of
it); writers without the SDK write the one known pair (:data:`FILE_ID`, :data:`CREATION_TIME`),
as Blender does.
"""
from __future__ import annotations

import struct
import zlib

import numpy as np

__all__ = ["Node", "Int64", "encode", "FILE_ID", "CREATION_TIME", "VERSION"]

VERSION = 7400
MAGIC = b"Kaydara FBX Binary  \x00\x1a\x00"
#: The ``FileId`` that goes with :data:`CREATION_TIME` (the SDK checks the pair).
FILE_ID = bytes.fromhex("28b32aebb624ccc2bfc8b02aa92bfcf1")
CREATION_TIME = "1970-01-01 10:00:00:000"
_FOOTER_ID = bytes.fromhex("fabcab09d0c8d466b176fb831cf7267e")
_CLOSING_ID = bytes.fromhex("f85a8c6adef5d97eece90ce3758f290b")
_NULL_RECORD = bytes(13)
#: Arrays whose raw data is longer than this are zlib-compressed (when that is smaller).
COMPRESS_ABOVE = 128
_ARRAY_CODES = {np.dtype(np.bool_): b"b", np.dtype("<i4"): b"i", np.dtype("<i8"): b"l",
                np.dtype("<f4"): b"f", np.dtype("<f8"): b"d"}
_UINT32_MAX = 2 ** 32 - 1


class Int64(int):
    """An integer written as FBX ``L`` (int64: object ids, times in ticks); a plain ``int``
    is ``I`` (int32)."""


class Node:
    """One FBX node record: a name, properties and child nodes.

    Parameters
    ----------
    name : str
    *props
        Each one of: ``bool`` (C), ``int`` (I), :class:`Int64` (L), ``float`` (D),
        ``np.float32`` (F), ``str`` (S, UTF-8), ``bytes`` (R), or a 1-D numpy array of bool,
        int32, int64, float32 or float64 (b, i, l, f, d).
    """

    __slots__ = ("name", "props", "children")

    def __init__(self, name, *props):
        self.name = name
        self.props = list(props)
        self.children = []

    def add(self, name, *props):
        """Append a child node and return it."""
        child = Node(name, *props)
        self.children.append(child)
        return child

    def append(self, node):
        """Append an existing node; returns it."""
        self.children.append(node)
        return node


def _array(value):
    arr = np.ascontiguousarray(value).reshape(-1)
    if arr.dtype.kind == "f" and arr.dtype not in _ARRAY_CODES:
        arr = arr.astype("<f8")
    arr = arr.astype(arr.dtype.newbyteorder("<"), copy=False)
    code = _ARRAY_CODES.get(arr.dtype)
    if code is None:
        raise TypeError(f"expected a bool, int32, int64, float32 or float64 array, "
                        f"got {arr.dtype}")
    raw = arr.tobytes()
    encoding, data = 0, raw
    if len(raw) > COMPRESS_ABOVE:
        packed = zlib.compress(raw, 6)
        if len(packed) < len(raw):
            encoding, data = 1, packed
    return code + struct.pack("<III", len(arr), encoding, len(data)) + data


def _property(value):
    """The type code and data of one property."""
    # bool before int (a bool is an int), Int64 before int, np.float32 before float
    if isinstance(value, (bool, np.bool_)):
        return b"C" + struct.pack("<?", bool(value))
    if isinstance(value, Int64):
        return b"L" + struct.pack("<q", value)
    if isinstance(value, (int, np.integer)):
        return b"I" + struct.pack("<i", int(value))
    if isinstance(value, np.float32):
        return b"F" + struct.pack("<f", value)
    if isinstance(value, (float, np.floating)):
        return b"D" + struct.pack("<d", float(value))
    if isinstance(value, str):
        data = value.encode("utf-8")
        return b"S" + struct.pack("<I", len(data)) + data
    if isinstance(value, (bytes, bytearray)):
        return b"R" + struct.pack("<I", len(value)) + bytes(value)
    if isinstance(value, np.ndarray):
        return _array(value)
    raise TypeError(f"expected an FBX property value, got {type(value).__name__}")


def _write(out, node, last):
    """Append ``node``'s record to ``out`` (whose length is the file offset so far)."""
    start = len(out)
    out += bytes(12)                        # end offset, property count, list length: below
    name = node.name.encode("utf-8")
    if len(name) > 255:
        raise ValueError(f"FBX node name longer than 255 bytes: {node.name[:40]!r}...")
    out.append(len(name))
    out += name
    first = len(out)
    for value in node.props:
        out += _property(value)
    length = len(out) - first
    for i, child in enumerate(node.children):
        _write(out, child, i == len(node.children) - 1)
    if node.children or (not node.props and not last):
        out += _NULL_RECORD
    if len(out) > _UINT32_MAX:
        raise ValueError("expected an FBX 7.4 file under 4 GiB (its offsets are 32-bit)")
    struct.pack_into("<III", out, start, len(out), len(node.props), length)


def encode(nodes, version=VERSION):
    """The bytes of a binary FBX file of the top-level ``nodes``.

    Parameters
    ----------
    nodes : list[Node]
    version : int
        Below 7500 (the 32-bit record layout written here).

    Returns
    -------
    bytes
    """
    if version >= 7500:
        raise ValueError(f"expected an FBX version below 7500, got {version}")
    out = bytearray(MAGIC + struct.pack("<I", version))
    for i, node in enumerate(nodes):
        _write(out, node, i == len(nodes) - 1)
    out += _NULL_RECORD
    out += _FOOTER_ID + bytes(4)
    out += bytes(16 - len(out) % 16)        # 1..16 zero bytes: a full 16 when aligned
    out += struct.pack("<I", version) + bytes(120) + _CLOSING_ID
    return bytes(out)
