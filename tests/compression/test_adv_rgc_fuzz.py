"""Adversarial .rgc files: truncated at every offset, bytes altered with the CRC32s made to
match again (a hostile file passes the checksum), hostile counts and values. Each must be
one RigFileError naming the file, or read to clips whose poses are finite and whose names
are clip names (a file that reads must not fail later, in a listing or at playback)."""
import struct
import zlib

import numpy as np
import pytest

from rigedit.animation import Clip, Track
from rigedit.compression import compress_clips
from rigedit.compression.layout import varint
from rigedit.errors import RigFileError
from rigedit.io.compressed_file import read_clip_file, save_compressed

from compression_characters import chain, mocap_clip


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """A small file: a 4-joint skeleton, a clip with rotations, a scale and a translation
    track (segmented and not), and a 2-key clip."""
    sk = chain(4, 0.1)
    base = mocap_clip(sk, frames=24, rate=30.0)
    t = np.arange(24) / 30.0
    tracks = dict(base.tracks)
    tracks[("j1", "scale")] = Track("scale", t, np.column_stack([1 + 0.3 * np.sin(3 * t)] * 3))
    clips = {"take": Clip("take", sk, tracks),
             "idle": Clip("idle", sk, {("j1", "rotation"): Track(
                 "rotation", [0, 1], [[0, 0, 0, 1], [0, 0, 0.1, 1]])})}
    packed = compress_clips(sk, clips, max_error=1e-4).clips
    path = tmp_path_factory.mktemp("rgc") / "small.rgc"
    save_compressed(path, sk, packed)
    return path.read_bytes()


def _sections(blob):
    """(offset, tag, size) of each section."""
    count = struct.unpack("<I", blob[8:12])[0]
    out, at = [], 12
    for _ in range(count):
        size = struct.unpack("<I", blob[at + 4:at + 8])[0]
        out.append((at, blob[at:at + 4], size))
        at += 12 + size
    return out


def _with_crcs(blob):
    """The blob with every section's CRC32 recomputed (what a hostile writer does)."""
    out = bytearray(blob)
    for at, _, size in _sections(blob):
        struct.pack_into("<I", out, at + 8, zlib.crc32(bytes(out[at + 12:at + 12 + size])))
    return bytes(out)


def _replace_clip(blob, index, payload):
    """The file with CLIP section ``index`` replaced by ``payload`` (CRC and length right)."""
    secs = _sections(blob)
    at, _, size = secs[1 + index]
    section = b"CLIP" + struct.pack("<II", len(payload), zlib.crc32(payload)) + payload
    return blob[:at] + section + blob[at + 12 + size:]


def _clip_payload(blob, index):
    at, _, size = _sections(blob)[1 + index]
    return blob[at + 12:at + 12 + size]


def _outcome(path, data):
    """None when the file reads to usable clips, else the error's message; anything other
    than a RigFileError naming the file fails the test."""
    path.write_bytes(data)
    try:
        _, clips = read_clip_file(path)
    except RigFileError as exc:
        assert path.name in str(exc)
        assert "\n" not in str(exc)
        return str(exc)
    for clip in clips.values():
        poses = clip.sample_many(np.linspace(-1.0, clip.duration + 1.0, 9))
        assert np.all(np.isfinite(poses)), clip.name
        clip.sample(0.5 * clip.duration)
        assert clip.to_clip().name == clip.name     # a valid clip name (Clip checks it)
    return None


def test_truncated_at_every_offset(small, tmp_path):
    path = tmp_path / "cut.rgc"
    messages = [_outcome(path, small[:cut]) for cut in range(len(small))]
    assert all(m is not None for m in messages)
    assert _outcome(path, small) is None


def test_every_byte_altered_with_matching_crcs(small, tmp_path):
    """Each byte of each section's payload set to 0, 0xFF and flipped in its low bit, the
    CRCs then fixed: refused in one line, or read to finite poses."""
    path = tmp_path / "flip.rgc"
    refused = 0
    for at, _, size in _sections(small):
        for off in range(at + 12, at + 12 + size):
            for value in {0x00, 0xFF, small[off] ^ 0x01} - {small[off]}:
                data = bytearray(small)
                data[off] = value
                refused += _outcome(path, _with_crcs(bytes(data))) is not None
    assert refused > 0


@pytest.mark.parametrize("name", [b"t\x00ke", b"a/b", b" take", b"\xff\xfe"])
def test_a_clip_name_no_clip_may_have_is_refused(small, tmp_path, name):
    """Used to read, and then fail in ``to_clip`` (a listing, the timeline) with Clip's
    ValueError: the reader now refuses it, naming the file."""
    payload = _clip_payload(small, 0)
    n = payload[0]                    # varint of a short name: one byte
    hostile = varint(len(name)) + name + payload[1 + n:]
    path = tmp_path / "name.rgc"
    msg = _outcome(path, _replace_clip(small, 0, hostile))
    assert msg is not None and "clip name" in msg


def _grid_payload(payload, duration=None, start=None, period=None, flags=None):
    """The payload with its duration, flags and (uniform) frame grid replaced."""
    n = payload[0]
    at = 1 + n
    d0, f0 = struct.unpack("<dB", payload[at:at + 9])
    head = struct.pack("<dB", d0 if duration is None else duration, f0 if flags is None
                       else flags)
    rest = payload[at + 9:]
    if start is None:
        return payload[:at] + head + rest
    assert f0 & 2, "the fixture's clip is on a uniform grid"
    count_bytes = 1 if rest[0] < 0x80 else 2
    s0, p0 = struct.unpack("<dd", rest[count_bytes:count_bytes + 16])
    grid = struct.pack("<dd", start, p0 if period is None else period)
    return payload[:at] + head + rest[:count_bytes] + grid + rest[count_bytes + 16:]


@pytest.mark.parametrize("change", [
    dict(duration=float("nan")), dict(duration=1e300), dict(duration=-1.0),
    dict(start=0.0, period=5e303), dict(start=1e300, period=0.0),
    dict(start=1e20, period=1e-10), dict(start=0.0, period=0.0),
    dict(start=float("nan"), period=1.0 / 30)])
def test_hostile_durations_and_frame_grids(small, tmp_path, change):
    """Huge or degenerate times used to read (an overflowing grid, frames all at one time:
    a division by zero in the decoder); now one error naming the file."""
    hostile = _grid_payload(_clip_payload(small, 0), **change)
    msg = _outcome(tmp_path / "grid.rgc", _replace_clip(small, 0, hostile))
    assert msg is not None


def test_huge_claimed_counts(small, tmp_path):
    """A section count, a section length and a clip's frame / track counts far beyond the
    file: refused before anything that size is allocated."""
    path = tmp_path / "huge.rgc"
    data = bytearray(small)
    struct.pack_into("<I", data, 8, 0xFFFFFFFF)
    assert "sections claimed" in _outcome(path, bytes(data))
    data = bytearray(small)
    struct.pack_into("<I", data, 12 + 4, 0xFFFFFFF0)
    assert "claims" in _outcome(path, bytes(data))
    payload = _clip_payload(small, 0)
    n = payload[0]
    at = 1 + n + 9
    count_bytes = 1 if payload[at] < 0x80 else 2
    for count in (1 << 40, 1 << 62):
        hostile = payload[:at] + varint(count) + payload[at + count_bytes:]
        assert _outcome(path, _replace_clip(small, 0, hostile)) is not None


@pytest.mark.parametrize("column, value", [(0, 1e300), (3, 1e300), (3, float("inf")),
                                           (7, float("nan"))])
def test_hostile_rest_values_in_the_skeleton(small, tmp_path, column, value):
    """A rest rotation of 1e300 overflowed its norm into a NaN skeleton (a RuntimeWarning,
    then NaN poses); now refused. ``column``: translation x, rotation x, scale x of joint 0."""
    at, _, size = _sections(small)[0]
    payload = bytearray(small[at + 12:at + 12 + size])
    joints = payload[0]
    names = 1
    for _ in range(joints):
        names += 1 + payload[names]
    base = names + 4 * joints
    offset = {0: base, 3: base + 24 * joints, 7: base + 56 * joints}[column]
    struct.pack_into("<d", payload, offset, value)
    data = bytearray(small)
    data[at + 12:at + 12 + size] = payload
    msg = _outcome(tmp_path / "rest.rgc", _with_crcs(bytes(data)))
    assert msg is not None and "rest" in msg
