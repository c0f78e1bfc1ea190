"""glTF 2.0 containers and accessors: the GLB/JSON file, its buffers, and typed arrays.

The JSON becomes pygltflib's objects (built directly from the parsed JSON: :mod:`rigedit.io.gltf_decode`);
this module checks the GLB container itself (pygltflib accepts a wrong version or chunk
lengths that disagree with the file) and decodes accessors
into numpy arrays in one vectorised step each: byte strides, sparse substitution, normalised
integers, matrix column padding, embedded GLB buffers, external ``.bin`` files and data URIs.
Every problem is one :class:`~rigedit.errors.RigFileError` naming the file.
"""
from __future__ import annotations

import base64
import json
import struct
import urllib.parse
from pathlib import Path

import numpy as np

from ..errors import RigFileError
from .gltf_checks import check_document
from .gltf_decode import decode as _decode
from .gltf_decode import lib as _lib
from .jsonfile import MAX_MAGNITUDE
from .paths import read_bytes

__all__ = ["GltfData", "COMPONENT_DTYPES", "TYPE_WIDTHS", "SUPPORTED_EXTENSIONS"]

GLB_MAGIC = b"glTF"
CHUNK_JSON = 0x4E4F534A
CHUNK_BIN = 0x004E4942

COMPONENT_DTYPES = {5120: np.dtype("<i1"), 5121: np.dtype("<u1"), 5122: np.dtype("<i2"),
                    5123: np.dtype("<u2"), 5125: np.dtype("<u4"), 5126: np.dtype("<f4")}
TYPE_WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
#: Largest value of each normalised integer type (signed ones clamp at -1, per the spec).
_NORM = {5120: 127.0, 5121: 255.0, 5122: 32767.0, 5123: 65535.0}
#: Extensions that change how geometry must be read and that rigedit implements.
SUPPORTED_EXTENSIONS = ("KHR_mesh_quantization",)
#: Bound on the elements (count x components) of the accessors that no bytes back (zero
#: filled, per the spec, when there is no bufferView): their count is only a claim. Such an
#: accessor mirrors data the file holds (a morph target's or sparse accessor's base), so at
#: most 4 elements per byte of the file and its buffers (a float VEC3 is 0.25 per byte), and
#: never more than 2**26 in all (512 MiB as float64).
CLAIM_ELEMENTS_PER_BYTE = 4
MAX_CLAIMED_ELEMENTS = 2**26


def _is_int(value):
    return isinstance(value, (int, np.integer)) and not isinstance(value, bool)


def _int(value, what, path, low=0):
    if not _is_int(value) or value < low:
        raise RigFileError(path, f"expected {what} to be an integer >= {low}, got {value!r}")
    return int(value)


class GltfData:
    """A parsed glTF file with decoded buffers.

    Parameters
    ----------
    path : str or Path
        A ``.glb`` or ``.gltf`` file (the container is recognised by its magic, not its name).
    allow_outside_uris : bool
        Read buffer and image URIs that leave the file's folder (absolute paths, ``..``,
        ``file:``). Off by default: a shared glTF could otherwise copy any file of the
        machine into the rig (and from there into an exported ``.glb``).

    Attributes
    ----------
    gltf : pygltflib.GLTF2
    path : Path
    """

    def __init__(self, path, allow_outside_uris=False):
        self.path = Path(path)
        self.allow_outside_uris = bool(allow_outside_uris)
        raw = read_bytes(self.path)  # a regular file of bounded size, FIFOs never opened
        self._size = len(raw)
        self._claimed = {}
        self._bin = None
        if raw[:4] == GLB_MAGIC:
            text = self._split_glb(raw)
        elif raw.lstrip()[:1] == b"{":
            text = raw
        else:
            raise RigFileError(self.path, f"expected a glTF file (JSON) or a GLB (magic 'glTF'), "
                                          f"got bytes {raw[:4]!r}")
        try:
            text = text.decode("utf-8")
            doc = json.loads(text)
        except (UnicodeDecodeError, ValueError) as exc:
            raise RigFileError(self.path, f"expected glTF JSON, got invalid JSON ({exc})") from None
        except RecursionError:
            raise RigFileError(self.path, "expected glTF JSON nested a few levels deep, got "
                                          "deeper nesting than the parser allows") from None
        if not isinstance(doc, dict) or not isinstance(doc.get("asset"), dict):
            raise RigFileError(self.path, "expected a glTF JSON object with an 'asset', got none")
        check_document(self.path, doc)
        version = str(doc["asset"].get("version", ""))
        if not version.startswith("2."):
            raise RigFileError(self.path, f"expected glTF version 2.x, got {version!r}")
        try:
            self.gltf = _decode(_lib().GLTF2, doc)
        except Exception as exc:  # a wrong type somewhere in the JSON
            raise RigFileError(self.path, f"expected valid glTF objects, got {exc}") from None
        required = list(self.gltf.extensionsRequired or [])
        missing = [e for e in required if e not in SUPPORTED_EXTENSIONS]
        if missing:
            raise RigFileError(self.path, f"the file requires the extension {missing[0]}, which "
                                          f"rigedit does not support (supported: "
                                          f"{', '.join(SUPPORTED_EXTENSIONS)})")
        self._buffers = {}

    # ------------------------------------------------------------------ container
    def _split_glb(self, raw):
        """Check a GLB header and chunks; keep the BIN chunk, return the JSON bytes."""
        if len(raw) < 20:
            raise RigFileError(self.path, f"expected a GLB header and a JSON chunk, got "
                                          f"{len(raw)} bytes")
        version, length = struct.unpack_from("<II", raw, 4)
        if version != 2:
            raise RigFileError(self.path, f"expected GLB container version 2, got {version}")
        if length != len(raw):
            raise RigFileError(self.path, f"expected the GLB length in the header ({length} "
                                          f"bytes) to equal the file size, got {len(raw)} bytes")
        chunks, offset = [], 12
        while offset < length:
            if offset + 8 > length:
                raise RigFileError(self.path, f"expected a chunk header at byte {offset}, got "
                                              "the end of the file")
            size, kind = struct.unpack_from("<II", raw, offset)
            if offset + 8 + size > length:
                raise RigFileError(self.path, f"expected chunk {len(chunks)} ({size} bytes at "
                                              f"byte {offset + 8}) to fit in the file of "
                                              f"{length} bytes, got it past the end")
            chunks.append((kind, raw[offset + 8:offset + 8 + size]))
            offset += 8 + size
        if not chunks or chunks[0][0] != CHUNK_JSON:
            raise RigFileError(self.path, "expected the first GLB chunk to be JSON, got "
                                          + (f"type 0x{chunks[0][0]:08x}" if chunks else "none"))
        if len(chunks) > 1 and chunks[1][0] == CHUNK_BIN:
            self._bin = chunks[1][1]
        return chunks[0][1]

    def item(self, kind, index, what):
        """``(index, object)`` of ``gltf.<kind>[index]``; a RigFileError when out of range."""
        items = getattr(self.gltf, kind) or []
        index = _int(index, f"{what} index", self.path)
        if index >= len(items):
            raise RigFileError(self.path, f"expected {what} index below {len(items)}, got "
                                          f"{index}")
        return index, items[index]

    def buffer(self, index):
        """The bytes of buffer ``index`` (GLB chunk, data URI or external file), cached."""
        index = _int(index, "a buffer index", self.path)
        if index in self._buffers:
            return self._buffers[index]
        index, buf = self.item("buffers", index, "buffer")
        where = f"buffer {index}"
        if buf.uri is None:
            if index != 0 or self._bin is None:
                raise RigFileError(self.path, f"{where}: expected a uri or the GLB binary chunk, "
                                              "got neither")
            data = self._bin
        else:
            data = self.uri_bytes(buf.uri, where)
        declared = _int(buf.byteLength, f"{where} byteLength", self.path, 1)
        if declared > len(data):
            raise RigFileError(self.path, f"{where}: expected {declared} bytes (byteLength), "
                                          f"got {len(data)}")
        self._buffers[index] = data
        return data

    def uri_bytes(self, uri, where):
        """Bytes behind a data URI or a file path relative to the glTF file."""
        if not isinstance(uri, str):
            raise RigFileError(self.path, f"{where}: expected a uri string, got {uri!r}")
        if uri.startswith("data:"):
            head, sep, payload = uri.partition(",")
            if not sep:
                raise RigFileError(self.path, f"{where}: expected a data URI with a comma, got "
                                              f"{uri[:40]!r}")
            try:
                if head.endswith(";base64"):
                    return base64.b64decode(payload, validate=True)
                return urllib.parse.unquote_to_bytes(payload)
            except ValueError as exc:
                raise RigFileError(self.path, f"{where}: bad base64 data ({exc})") from None
        target = self._uri_path(uri, where)
        try:
            return read_bytes(target)
        except RigFileError as exc:  # named from the glTF file, which the user opened
            raise RigFileError(self.path, f"{where}: cannot read {target} ({exc.problem})") \
                from None

    def _uri_path(self, uri, where):
        """The file a (non-data) URI names, refused when it leaves the glTF's folder (an
        absolute path, ``..`` climbing out, a ``file:`` URI, a symbolic link pointing out)
        unless ``allow_outside_uris``; other schemes (``http:``) are never fetched."""
        scheme = urllib.parse.urlsplit(uri).scheme
        if scheme == "file":
            if not self.allow_outside_uris:
                raise RigFileError(self.path, f"{where}: expected a uri relative to the file's "
                                              f"folder, got {uri[:80]!r} (a file: uri; allow "
                                              "it with --allow-outside-uris)")
            return Path(urllib.parse.unquote(urllib.parse.urlsplit(uri).path))
        if len(scheme) > 1:  # one letter is a Windows drive (C:/...), an absolute path
            raise RigFileError(self.path, f"{where}: expected a file or data uri, got a "
                                          f"{scheme}: uri (rigedit fetches nothing)")
        relative = urllib.parse.unquote(uri)
        target = self.path.parent / relative
        if self.allow_outside_uris:
            return target
        folder = self.path.parent.resolve()
        try:
            inside = target.resolve().is_relative_to(folder)
        except (OSError, RuntimeError, ValueError):  # a symlink loop, a NUL byte
            inside = False
        if Path(relative).is_absolute() or len(scheme) == 1 or not inside:
            raise RigFileError(self.path, f"{where}: expected a uri inside the file's folder, "
                                          f"got {uri[:80]!r} (allow it with "
                                          "--allow-outside-uris)")
        return target

    def view_bytes(self, index, where):
        """(bytes, stride or None) of buffer view ``index``, bounds checked."""
        index, view = self.item("bufferViews", index, f"{where}: bufferView")
        data = self.buffer(view.buffer)
        start = _int(view.byteOffset or 0, f"bufferView {index} byteOffset", self.path)
        length = _int(view.byteLength, f"bufferView {index} byteLength", self.path, 1)
        if start + length > len(data):
            raise RigFileError(self.path, f"bufferView {index}: expected bytes {start}.."
                                          f"{start + length} inside buffer {view.buffer} of "
                                          f"{len(data)} bytes, got past its end")
        stride = view.byteStride
        if stride is not None:
            stride = _int(stride, f"bufferView {index} byteStride", self.path, 4)
        return memoryview(data)[start:start + length], stride

    # ------------------------------------------------------------------ accessors
    def _strided(self, view, offset, count, dtype, width, stride, where, matrix=False):
        """(count, width) array of ``dtype`` read from ``view`` at ``offset`` every ``stride``
        bytes (``stride`` None: tightly packed). Matrix columns of 1- and 2-byte components
        are padded to 4 bytes, as the spec lays them out."""
        size = dtype.itemsize
        rows, cols = {4: (2, 2), 9: (3, 3), 16: (4, 4)}[width] if matrix else (width, 1)
        col_bytes = size * rows
        col_stride = -(-col_bytes // 4) * 4 if cols > 1 and size < 4 else col_bytes
        elem = col_stride * cols
        stride = stride or elem
        if stride < elem:
            raise RigFileError(self.path, f"{where}: expected a byteStride of at least {elem}, "
                                          f"got {stride}")
        end = offset + stride * (count - 1) + elem if count else offset
        if end > len(view):
            raise RigFileError(self.path, f"{where}: expected {count} elements from byte "
                                          f"{offset} to fit in its bufferView of {len(view)} "
                                          f"bytes, got past its end (byte {end})")
        if count == 0:
            return np.zeros((0, width), dtype=dtype)
        block = np.frombuffer(view, dtype=np.uint8, count=end - offset, offset=offset)
        block = np.concatenate([block, np.zeros(stride * count - len(block), np.uint8)])
        block = block.reshape(count, stride)
        parts = [block[:, c * col_stride:c * col_stride + col_bytes] for c in range(cols)]
        packed = np.ascontiguousarray(np.concatenate(parts, axis=1))
        return packed.view(dtype).reshape(count, width)

    def accessor(self, index, where="accessor"):
        """Decode accessor ``index``.

        Returns
        -------
        values : (count, width) ndarray
            float64 for float and normalised accessors, the integer type otherwise. Matrices
            are flattened column-major, as stored (reshape to (n, 4, 4) and transpose).
        """
        index, acc = self.item("accessors", index, f"{where}: accessor")
        where = f"accessor {index} ({where})"
        dtype = COMPONENT_DTYPES.get(acc.componentType) if _is_int(acc.componentType) else None
        width = TYPE_WIDTHS.get(acc.type) if isinstance(acc.type, str) else None
        if dtype is None or width is None:
            raise RigFileError(self.path, f"{where}: expected a known componentType and type, "
                                          f"got {acc.componentType!r} {acc.type!r}")
        count = _int(acc.count, f"{where} count", self.path, 1)
        if acc.bufferView is None:
            self._claim(index, count * width, where)
            out = np.zeros((count, width), dtype=dtype)
        else:
            view, stride = self.view_bytes(acc.bufferView, where)
            offset = _int(acc.byteOffset or 0, f"{where} byteOffset", self.path)
            out = self._strided(view, offset, count, dtype, width, stride, where,
                                matrix=acc.type.startswith("MAT")).copy()
        if acc.sparse is not None:
            self._apply_sparse(acc, out, dtype, width, where)
        if dtype.kind == "f":
            out = out.astype(np.float64)
            self._check_values(out, where)
            return out
        if acc.normalized:
            if acc.componentType not in _NORM:
                raise RigFileError(self.path, f"{where}: expected a normalised byte or short, "
                                              f"got componentType {acc.componentType}")
            return np.maximum(out / _NORM[acc.componentType], -1.0)
        return out

    def _check_values(self, values, where):
        """Refuse NaN, inf and magnitudes beyond :data:`~rigedit.io.jsonfile.MAX_MAGNITUDE`
        (10^9): such numbers overflow float32 skinning once multiplied through a joint chain,
        and a rig folder or BVH written from them would not load back."""
        bad = ~(np.abs(values) <= MAX_MAGNITUDE)   # NaN compares false
        if bad.any():
            value = values[bad][0]
            raise RigFileError(self.path, f"{where}: expected finite values within "
                                          f"+-{MAX_MAGNITUDE:g}, got {value:g}")

    def _claim(self, index, elements, where):
        """Allow a zero-filled accessor of ``elements`` only within the file's bound."""
        self._claimed[index] = elements
        total = sum(self._claimed.values())
        # the buffers' declared lengths (checked against their bytes when they are read):
        # the bound holds before any external buffer is loaded
        data = self._size + sum(b.byteLength for b in self.gltf.buffers or []
                                if _is_int(b.byteLength) and b.byteLength > 0)
        bound = min(MAX_CLAIMED_ELEMENTS, max(2**16, CLAIM_ELEMENTS_PER_BYTE * data))
        if total > bound:
            raise RigFileError(self.path, f"{where}: expected accessors without a bufferView "
                                          f"of at most {bound} elements in all (what a file of "
                                          f"{data} bytes can justify), got {total}")

    def _apply_sparse(self, acc, out, dtype, width, where):
        sparse = acc.sparse
        n = _int(sparse.count, f"{where} sparse count", self.path, 1)
        ind = sparse.indices
        if ind is None or sparse.values is None:
            raise RigFileError(self.path, f"{where}: expected sparse 'indices' and 'values', "
                                          "got one missing")
        if not _is_int(ind.componentType) or ind.componentType not in (5121, 5123, 5125):
            raise RigFileError(self.path, f"{where}: expected sparse indices of unsigned type, "
                                          f"got componentType {ind.componentType!r}")
        view, _ = self.view_bytes(ind.bufferView, f"{where} sparse indices")
        idx = self._strided(view, _int(ind.byteOffset or 0, "sparse byteOffset", self.path), n,
                            COMPONENT_DTYPES[ind.componentType], 1, None, f"{where} sparse indices")[:, 0].astype(np.int64)
        if idx.max() >= len(out) or np.any(np.diff(idx) <= 0):
            raise RigFileError(self.path, f"{where}: expected strictly increasing sparse indices "
                                          f"below {len(out)}, got {idx.min()}..{idx.max()}")
        val = sparse.values
        view, _ = self.view_bytes(val.bufferView, f"{where} sparse values")
        out[idx] = self._strided(view, _int(val.byteOffset or 0, "sparse byteOffset", self.path),
                                 n, dtype, width, None, f"{where} sparse values",
                                 matrix=acc.type.startswith("MAT"))

    def image_bytes(self, index):
        """(bytes, mime type or None) of image ``index``."""
        index, image = self.item("images", index, "image")
        where = f"image {index}"
        if image.bufferView is not None:
            view, _ = self.view_bytes(image.bufferView, where)
            return bytes(view), image.mimeType
        data = self.uri_bytes(image.uri, where)
        mime = image.mimeType
        if mime is None:  # a uri needs no mimeType: tell PNG and JPEG by their signature
            mime = ("image/png" if data[:8] == b"\x89PNG\r\n\x1a\n" else
                    "image/jpeg" if data[:3] == b"\xff\xd8\xff" else None)
        return data, mime
