"""rigedit's compressed clip file (``.rgc``): a skeleton and compressed clips, checksummed.

==========  ===============================================================================
bytes       what
==========  ===============================================================================
4           magic ``b"RGC1"``
2, 2        uint16 version (1), uint16 flags (0)
4           uint32 number of sections
sections    each: 4-byte ASCII tag, uint32 payload length, uint32 CRC32 of the payload,
            the payload; first one ``SKEL``, then one ``CLIP`` per clip
==========  ===============================================================================

``SKEL``: varint J; J names (varint length, UTF-8); J int32 parents (-1 a root, parents
before children); J x 3 float64 rest translations, J x 4 rest rotations (x, y, z, w),
J x 3 rest scales; J uint8 deform flags. ``CLIP``: one compressed clip
(:mod:`rigedit.compression.layout`). Little-endian throughout. Every length is checked
against the bytes that are left before anything is allocated for it, and every section's
CRC32 before it is parsed: a truncated or altered file is one :class:`RigFileError`.
"""
from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np

from ..compression import CompressedClip, compress_clips
from ..compression.layout import ByteReader, LayoutError, varint
from ..errors import RigFileError
from ..model.skeleton import Skeleton
from .atomic import atomic_write
from .data import RigData, RigMeta

__all__ = ["MAGIC", "SUFFIX", "DEFAULT_MAX_ERROR", "read_compressed", "write_compressed",
           "save_compressed", "skeleton_bytes", "read_clip_file"]

MAGIC = b"RGC1"
SUFFIX = ".rgc"
VERSION = 1
#: The bound (metres) plain clips are compressed at when written as .rgc without one.
DEFAULT_MAX_ERROR = 1e-4
#: Largest .rgc file read (bytes): a bound on what a file can make rigedit allocate.
MAX_FILE_BYTES = 1 << 31
#: Largest rest translation, rotation component or scale read (metres, units): beyond any
#: rig, and small enough that forward kinematics stays finite.
MAX_REST_VALUE = 1e9


def _section(tag, payload):
    return tag + struct.pack("<II", len(payload), zlib.crc32(payload)) + payload


def skeleton_bytes(skeleton):
    """The ``SKEL`` payload of a skeleton."""
    out = bytearray(varint(len(skeleton)))
    for name in skeleton.names:
        raw = name.encode("utf-8")
        out += varint(len(raw)) + raw
    out += np.asarray(skeleton.parents, dtype="<i4").tobytes()
    for arr in (skeleton.rest_translation, skeleton.rest_rotation, skeleton.rest_scale):
        out += np.asarray(arr, dtype="<f8").tobytes()
    out += np.asarray(skeleton.deform, dtype=np.uint8).tobytes()
    return bytes(out)


def _read_skeleton(payload):
    r = ByteReader(payload)
    count = r.varint("joint count", len(payload) // 45)   # 45: the fewest bytes per joint
    names = [bytes(r.take(r.varint("joint name length", len(payload)), "joint name")).decode(
        "utf-8") for _ in range(count)]
    parents = np.frombuffer(r.take(4 * count, "parents"), dtype="<i4").astype(np.int64)
    rest = [r.floats(count * w, what, "<f8").reshape(count, w)
            for w, what in ((3, "rest translations"), (4, "rest rotations"), (3, "rest scales"))]
    deform = np.frombuffer(r.take(count, "deform flags"), dtype=np.uint8) > 0
    # checked here, not by Skeleton: 1e300 is finite but overflows the quaternion's norm
    if not all(np.all(np.abs(a) <= MAX_REST_VALUE) for a in rest):   # also refuses NaN
        raise LayoutError(f"skeleton: a rest value is not finite or beyond "
                          f"{MAX_REST_VALUE:g}")
    if count and np.min(np.linalg.norm(rest[1], axis=1)) < 1e-6:
        raise LayoutError("skeleton: a rest rotation is not a rotation (zero quaternion)")
    if r.at != len(payload):
        raise LayoutError(f"skeleton: {len(payload) - r.at} bytes after its end")
    return Skeleton(names, parents, *rest, deform=deform)


def _sections(path, blob):
    """``[(tag, payload)]`` of a file's bytes, every CRC checked."""
    if len(blob) < 12 or blob[:4] != MAGIC:
        raise RigFileError(path, "expected a rigedit compressed clip file (magic RGC1), got "
                                 f"{'a file too short' if len(blob) < 12 else 'other bytes'}")
    version, _flags, count = struct.unpack("<HHI", blob[4:12])
    if version != VERSION:
        raise RigFileError(path, f"expected .rgc version {VERSION}, got {version}")
    if count > (len(blob) - 12) // 12:
        raise RigFileError(path, f"{count} sections claimed, the file holds at most "
                                 f"{(len(blob) - 12) // 12}: truncated or corrupted")
    at, out = 12, []
    for i in range(count):
        if at + 12 > len(blob):
            raise RigFileError(path, f"truncated: section {i + 1} of {count} is missing")
        tag = bytes(blob[at:at + 4])
        size, crc = struct.unpack("<II", blob[at + 4:at + 12])
        if size > len(blob) - at - 12:
            raise RigFileError(path, f"truncated: section {i + 1} ({tag!r}) claims {size} "
                                     f"bytes, {len(blob) - at - 12} left")
        payload = blob[at + 12:at + 12 + size]
        if zlib.crc32(payload) != crc:
            raise RigFileError(path, f"corrupted: section {i + 1} ({tag.decode('ascii', 'replace')}) "
                                     "fails its CRC32 check")
        out.append((tag, payload))
        at += 12 + size
    if at != len(blob):
        raise RigFileError(path, f"{len(blob) - at} bytes after the last section")
    return out


def read_clip_file(path, skeleton=None):
    """The skeleton and clips of an .rgc file: ``(Skeleton, {name: CompressedClip})``.

    ``skeleton``: read the clips onto this one instead (a rig folder's), which must have the
    file's joints in its order.
    """
    path = Path(path)
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise RigFileError(path, f"cannot read: {exc.strerror or exc}") from None
    if size > MAX_FILE_BYTES:
        raise RigFileError(path, f"{size} bytes, expected at most {MAX_FILE_BYTES}")
    try:
        blob = path.read_bytes()
    except OSError as exc:
        raise RigFileError(path, f"cannot read: {exc.strerror or exc}") from None
    sections = _sections(path, blob)
    if not sections or sections[0][0] != b"SKEL":
        raise RigFileError(path, "expected a SKEL section first, got "
                                 f"{sections[0][0] if sections else 'no sections'}")
    clips = {}
    try:
        own = _read_skeleton(sections[0][1])
        if skeleton is not None and list(skeleton.names) != own.names:
            raise RigFileError(path, f"expected the rig's {len(skeleton)} joints in order, "
                                     f"got {len(own)} other joints")
        skeleton = own if skeleton is None else skeleton
        for tag, payload in sections[1:]:
            if tag != b"CLIP":
                raise RigFileError(path, f"unknown section {tag!r}")
            clip = CompressedClip(skeleton, payload)
            if clip.name in clips:
                raise RigFileError(path, f"two clips named {clip.name!r}")
            clips[clip.name] = clip
    except (LayoutError, ValueError, UnicodeDecodeError) as exc:
        if isinstance(exc, RigFileError):
            raise
        raise RigFileError(path, f"corrupted: {exc}") from None
    return skeleton, clips


def read_compressed(path):
    """The registry's reader: an .rgc file as a mesh-less :class:`RigData` whose clips are
    :class:`~rigedit.compression.CompressedClip` objects (played straight from their bits)."""
    path = Path(path)
    skeleton, clips = read_clip_file(path)
    meta = RigMeta(source=path, format="rgc", notes={
        "compressed": f"{len(clips)} compressed clips: played as stored, not editable"})
    return RigData(skeleton, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64),
                   np.zeros((0, 1), dtype=np.int64), np.zeros((0, 1)), clips,
                   name=path.stem, meta=meta)


def save_compressed(path, skeleton, clips):
    """Write ``skeleton`` and compressed ``clips`` (name -> CompressedClip) to ``path``,
    atomically."""
    sections = [_section(b"SKEL", skeleton_bytes(skeleton))]
    sections += [_section(b"CLIP", clip.blob) for clip in clips.values()]
    with atomic_write(path, "wb") as fh:
        fh.write(MAGIC + struct.pack("<HHI", VERSION, 0, len(sections)))
        for s in sections:
            fh.write(s)


def write_compressed(data, path, clips=None, max_error=DEFAULT_MAX_ERROR):
    """The registry's writer: the rig's skeleton and clips (``clips``: names, all when None);
    plain clips are compressed at ``max_error`` metres (3 cm shell), compressed ones written
    as they are."""
    names = list(data.clips) if clips is None else list(clips)
    chosen = {n: data.clips[n] for n in names}
    plain = {n: c for n, c in chosen.items() if not isinstance(c, CompressedClip)}
    if plain:
        packed = compress_clips(data.skeleton, plain, max_error=max_error).clips
        chosen = {n: packed.get(n, c) for n, c in chosen.items()}
    save_compressed(path, data.skeleton, chosen)
