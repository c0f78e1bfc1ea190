"""rigedit's .rgc file: round trip through load_rig / save_rig, and every truncation or
altered byte is one RigFileError naming the file."""
import sys
from pathlib import Path

import numpy as np
import pytest

import rigedit
from rigedit.compression import CompressedClip, compress_clips
from rigedit.errors import RigFileError
from rigedit.io.compressed_file import read_clip_file, save_compressed

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "compression"))
from compression_characters import chain, mocap_clip  # noqa: E402


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    sk = chain(8, 0.1)
    clips = {"a": mocap_clip(sk, 60, name="a"), "b": mocap_clip(sk, 30, seed=4, name="b",
                                                                loop=True)}
    result = compress_clips(sk, clips, max_error=1e-4)
    path = tmp_path_factory.mktemp("rgc") / "clips.rgc"
    save_compressed(path, sk, result.clips)
    return path, sk, clips, result


def test_round_trip_through_load_rig(written):
    path, sk, clips, result = written
    rig = rigedit.load_rig(path)
    assert rig.skeleton.names == sk.names
    assert np.allclose(rig.skeleton.rest_translation, sk.rest_translation)
    assert set(rig.clips) == {"a", "b"} and rig.clips["b"].loop
    for name, clip in rig.clips.items():
        assert isinstance(clip, CompressedClip)
        assert clip.blob == result.clips[name].blob
        times = np.linspace(0, clip.duration, 17)
        assert np.allclose(clip.sample_many(times), result.clips[name].sample_many(times))
    assert "compressed" in rig.meta.notes


def test_save_rig_compresses_plain_clips(tmp_path):
    sk = chain(4, 0.1)
    rig = rigedit.Rig(sk, np.zeros((0, 3)), np.zeros((0, 3), dtype=int),
                      np.zeros((0, 1), dtype=int), np.zeros((0, 1)),
                      clips={"take": mocap_clip(sk, 40)})
    rigedit.save_rig(rig, tmp_path / "x.rgc")
    back = rigedit.load_rig(tmp_path / "x.rgc")
    from rigedit.compression import measure_error
    assert measure_error(sk, rig.clips["take"], back.clips["take"]).max() <= 1e-4


def test_every_truncation_is_one_error(written, tmp_path):
    path, *_ = written
    blob = path.read_bytes()
    bad = tmp_path / "cut.rgc"
    for cut in list(range(0, 40)) + list(range(40, len(blob), max(len(blob) // 60, 1))):
        bad.write_bytes(blob[:cut])
        with pytest.raises(RigFileError) as info:
            read_clip_file(bad)
        assert str(bad) in str(info.value) and "\n" not in str(info.value)


def test_altered_bytes_fail_the_checksum(written, tmp_path):
    path, *_ = written
    blob = bytearray(path.read_bytes())
    bad = tmp_path / "flip.rgc"
    rng = np.random.default_rng(0)
    for at in rng.integers(12, len(blob), 40):
        copy = bytearray(blob)
        copy[at] ^= 0x5A
        bad.write_bytes(bytes(copy))
        with pytest.raises(RigFileError, match=str(bad)):
            read_clip_file(bad)


def test_huge_claims_are_refused_before_allocating(tmp_path):
    import struct
    bad = tmp_path / "claim.rgc"
    bad.write_bytes(b"RGC1" + struct.pack("<HHI", 1, 0, 2 ** 31) + b"\0" * 20)
    with pytest.raises(RigFileError, match="sections claimed"):
        read_clip_file(bad)
    bad.write_bytes(b"RGC1" + struct.pack("<HHI", 1, 0, 1) + b"SKEL" + struct.pack("<II", 2**31, 0))
    with pytest.raises(RigFileError, match="truncated"):
        read_clip_file(bad)
    bad.write_bytes(b"not a clip file at all")
    with pytest.raises(RigFileError, match="magic"):
        rigedit.load_rig(bad)


def test_rig_folder_keeps_compressed_clips_beside_json_ones(tmp_path):
    from builders import cylinder_rig

    rig = cylinder_rig()
    sk = rig.skeleton
    rig.clips["take"] = mocap_clip(sk, 40)
    packed = compress_clips(sk, {"take": rig.clips["take"]}, max_error=1e-4).clips["take"]
    rig.clips["take"] = packed
    folder = tmp_path / "rig"
    rigedit.save_rig(rig, folder)
    files = sorted(p.name for p in (folder / "animations").iterdir())
    assert files == ["bend.json", "take.rgc"]
    back = rigedit.load_rig(folder)
    assert isinstance(back.clips["take"], CompressedClip)
    assert back.clips["take"].blob == packed.blob
    assert not isinstance(back.clips["bend"], CompressedClip)
    # the clip made plain again: its .rgc is rigedit's stale file, replaced by a .json
    back.clips["take"] = back.clips["take"].to_clip()
    rigedit.save_rig(back, folder)
    assert sorted(p.name for p in (folder / "animations").iterdir()) == ["bend.json",
                                                                          "take.json"]
    again = rigedit.load_rig(folder)
    times = np.linspace(0, packed.duration, 9)
    assert np.allclose(again.clips["take"].sample(times[3]).as_array(),
                       packed.sample(times[3]).as_array(), atol=1e-9)


def test_rig_folder_refuses_a_compressed_clip_of_other_joints(tmp_path):
    from builders import cylinder_rig

    rig = cylinder_rig()
    rigedit.save_rig(rig, tmp_path / "rig")
    other = chain(5, 0.1)
    packed = compress_clips(other, {"x": mocap_clip(other, 10, name="x")}).clips
    save_compressed(tmp_path / "rig" / "animations" / "x.rgc", other, packed)
    with pytest.raises(RigFileError, match="x.rgc.*joints"):
        rigedit.load_rig(tmp_path / "rig")


def test_a_compressed_rig_saves_to_other_formats(written, tmp_path):
    path, sk, clips, result = written
    rig = rigedit.load_rig(path)
    with pytest.warns(UserWarning):   # the writer says how to read a small figure back
        rigedit.save_rig(rig, tmp_path / "a.bvh", clips=["a"])
    back = rigedit.load_rig(tmp_path / "a.bvh", scale=0.01)
    from rigedit.compression import measure_error
    err = measure_error(sk, clips["a"], back.clips[next(iter(back.clips))])
    assert err.max() < 2e-4      # the bound, plus BVH's printed digits
    copy = rig.clips["a"].copy("edit me")
    copy.set_key("j1", "rotation", 0.1, [0, 0, 0, 1])   # a plain clip: editable
    assert copy.name == "edit me" and ("j1", "rotation") in rig.clips["a"].tracks


def test_well_checksummed_nonsense_is_one_error(written, tmp_path):
    """A file whose CRCs match but whose contents do not make sense (a writer's bug, a
    crafted file): one RigFileError, never a traceback or a huge allocation."""
    import struct
    import zlib
    path, sk, *_ = written
    blob = path.read_bytes()
    size = struct.unpack("<I", blob[16:20])[0]
    skel = bytearray(blob[24:24 + size])
    clip_at = 24 + size
    bad = tmp_path / "crafted.rgc"

    def write(skel_payload, rest=blob[clip_at:]):
        head = b"RGC1" + struct.pack("<HHI", 1, 0, 1 + (len(rest) > 0) * 2)
        bad.write_bytes(head + b"SKEL" + struct.pack("<II", len(skel_payload),
                                                     zlib.crc32(skel_payload))
                        + skel_payload + rest)

    cyclic = bytearray(skel)
    at = 1 + sum(1 + len(n.encode()) for n in sk.names)
    cyclic[at:at + 4] = struct.pack("<i", 5)          # the root's parent after it
    write(bytes(cyclic))
    with pytest.raises(RigFileError, match="crafted.rgc"):
        read_clip_file(bad)
    huge = bytearray(skel)
    huge[0:1] = b"\x7f"                                   # 127 joints claimed
    write(bytes(huge))
    with pytest.raises(RigFileError, match="crafted.rgc"):
        read_clip_file(bad)
