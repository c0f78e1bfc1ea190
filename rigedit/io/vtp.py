"""VTK XML PolyData (.vtp) meshes: checked by rigedit, then read by VTK.

VTK trusts a file's own numbers: a corrupted compression header made it spend seconds reading
(found by tests/test_fuzz_io.py), and a Piece claiming 10^12 points would be allocated. So the
XML is parsed here first and the claims bounded by the file's size before VTK sees it.
"""
from __future__ import annotations

import base64
import binascii
import struct
import xml.etree.ElementTree as ET

import numpy as np

from ..errors import RigFileError
from .mesh_common import third_party_read, triangulate
from .paths import read_bytes

__all__ = ["read_vtp", "check_vtp"]

#: zlib cannot compress better than about 1032:1; a claim beyond that is not in the file.
MAX_RATIO = 1100


def _count(path, element, key, limit):
    try:
        value = int(element.get(key, "0"))
    except ValueError:
        raise RigFileError(path, f"expected {key} to be an integer, got "
                                 f"{element.get(key)[:40]!r}") from None
    if not 0 <= value <= limit:
        raise RigFileError(path, f"expected {key} from 0 to {limit} for a file of this size, "
                                 f"got {value}")
    return value


def _check_binary_array(path, array, text, size, compressed, limit):
    name = array.get("Name", "?")
    fmt = "<" + ("Q" if size == 8 else "I")
    try:
        if compressed:
            # header: number of blocks, block size, last block size, then each block's
            # compressed size, base64-encoded on its own before the data
            nblocks, block, last = struct.unpack(fmt[0] + fmt[1] * 3,
                                                 base64.b64decode(text[:4 * size], validate=True))
            claimed = nblocks * block
            header_chars = 4 * -(-(3 + nblocks) * size // 3)
            if nblocks > len(text) or header_chars > len(text) or last > block:
                raise ValueError(f"a compression header of {nblocks} blocks")
        else:
            claimed = struct.unpack(fmt, base64.b64decode(text[:4 * -(-size // 3)])[:size])[0]
            if claimed > len(text):
                raise ValueError(f"{claimed} bytes in {len(text)} characters")
    except (ValueError, binascii.Error, struct.error) as exc:
        raise RigFileError(path, f"DataArray {name!r}: expected base64 data with a sane "
                                 f"header, got {str(exc)[:80]}") from None
    if claimed > limit:
        raise RigFileError(path, f"DataArray {name!r}: expected at most {limit} bytes of data "
                                 f"for a file of this size, got a claim of {claimed}")


def check_vtp(path):
    """``RigFileError`` unless ``path`` is well-formed VTK XML PolyData whose counts and
    binary headers fit in the file (raw appended data is left to VTK)."""
    data = read_bytes(path)
    limit = MAX_RATIO * max(len(data), 1)
    cut = data.find(b"<AppendedData")
    xml = data if cut < 0 else data[:cut] + b"</VTKFile>"
    try:
        root = ET.fromstring(xml)
    except ET.ParseError as exc:
        raise RigFileError(path, f"expected VTK XML, got malformed XML ({exc})") from None
    if root.tag != "VTKFile" or root.get("type") != "PolyData":
        raise RigFileError(path, f"expected a VTKFile of type PolyData, got {root.tag} "
                                 f"{root.get('type')!r}")
    for piece in root.iter("Piece"):
        for key in ("NumberOfPoints", "NumberOfVerts", "NumberOfLines", "NumberOfStrips",
                    "NumberOfPolys"):
            _count(path, piece, key, limit // 8)
    size = 8 if root.get("header_type") == "UInt64" else 4
    compressed = root.get("compressor") is not None
    for array in root.iter("DataArray"):
        if array.get("format") == "binary":
            text = "".join((array.text or "").split()).encode("ascii", "replace")
            _check_binary_array(path, array, text, size, compressed, limit)


def read_vtp(path):
    """Points (V, 3) float64 and triangles (F, 3) int64 of a VTK XML PolyData file."""
    check_vtp(path)
    # VTP (XML PolyData) is not among meshio's formats; VTK reads it. This is the one place
    # below rigedit/render that touches VTK, and only when a VTP file is opened. VTK prints a
    # bad file's errors to the terminal from C++ (its logger and output window, observers
    # see only some of them): display is off for the read, and an empty result is the error.
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkCommonCore import vtkObject
    from vtkmodules.vtkFiltersCore import vtkTriangleFilter
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader

    def read():
        reader = vtkXMLPolyDataReader()
        reader.SetFileName(str(path))
        tri = vtkTriangleFilter()
        tri.SetInputConnection(reader.GetOutputPort())
        tri.PassVertsOff()
        tri.PassLinesOff()
        tri.Update()
        return reader.GetErrorCode(), tri.GetOutput()

    shown = vtkObject.GetGlobalWarningDisplay()
    vtkObject.GlobalWarningDisplayOff()
    try:
        code, poly = third_party_read(path, read)
    finally:
        vtkObject.SetGlobalWarningDisplay(shown)
    if poly is None or poly.GetNumberOfPoints() == 0 or poly.GetPolys() is None:
        raise RigFileError(path, "cannot read mesh: expected VTK XML PolyData with points, "
                                 f"got none (VTK error code {code})")
    points = vtk_to_numpy(poly.GetPoints().GetData()).astype(np.float64)
    conn = vtk_to_numpy(poly.GetPolys().GetConnectivityArray()).astype(np.int64)
    return points, conn.reshape(-1, 3) if len(conn) % 3 == 0 else triangulate([])


