"""The compact glTF writer (rigedit.io.gltf_write_compact) on clips of reduced keys built by
hand: the Khronos validator finds nothing, rigedit reads back what was written, rotations are
normalised SHORT, equal key times share one accessor, rest tracks are left out, meshopt views
decode to the plain file's bytes."""
from __future__ import annotations

import json
import struct

import numpy as np
import pygltflib
import pytest

import rigedit
from rigedit.animation.clip import Clip, Track
from rigedit.errors import RigFileError
from rigedit.io.gltf_write_compact import MESHOPT, meshopt_available, save_gltf_compressed

from compact_helpers import decoded_rotation, reduced_clip, validate


@pytest.fixture(scope="module")
def rig():
    return rigedit.load_rig("humanoid")


@pytest.fixture(scope="module")
def clips(rig):
    return {"walk_reduced": reduced_clip(rig, "walk", every=4),
            "wave_reduced": reduced_clip(rig, "wave", every=3, duration_extra=0.25)}


def _doc(path):
    return pygltflib.GLTF2().load(str(path))


@pytest.mark.parametrize("ext", [".glb", ".gltf"])
@pytest.mark.parametrize("meshopt", [False, True])
def test_khronos_validator_finds_nothing(tmp_path, rig, clips, ext, meshopt):
    if meshopt and not meshopt_available():
        pytest.skip("the meshopt package is not installed (rigedit[meshopt])")
    out = tmp_path / f"c{ext}"
    save_gltf_compressed(rig, out, clips, meshopt=meshopt)
    issues = validate(out)
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"][:5]
    if meshopt:   # the validator does not decode the extension: it says so as an info
        assert any(m["code"] == "UNSUPPORTED_EXTENSION" for m in issues["messages"])


def test_reads_back_the_keys_as_written(tmp_path, rig, clips):
    out = tmp_path / "c.glb"
    save_gltf_compressed(rig, out, clips)
    back = rigedit.load_rig(out)
    assert set(back.clips) == set(clips)
    for name, clip in clips.items():
        got = back.clips[name]
        assert got.duration == pytest.approx(clip.duration) and got.loop == clip.loop
        for key, tr in clip.tracks.items():
            if len(tr.times) == 1 and key[1] == "scale" and np.all(tr.values == 1):
                assert key not in got.tracks      # the rest: left out
                continue
            g = got.tracks[key]
            values = tr.values
            if len(g.times) == len(tr.times) + 1:   # the hold key at the duration
                assert g.times[-1] == pytest.approx(clip.duration, abs=1e-6)
                values = np.vstack([values, values[-1:]])
            np.testing.assert_allclose(g.times[:len(tr.times)], tr.times, atol=1e-6)
            if key[1] == "rotation":
                want = decoded_rotation(values)
                assert np.abs(np.abs(np.sum(g.values * want, axis=1)) - 1).max() < 1e-12
                # int16 rounding moves a unit quaternion by at most 1/32767 per component
                assert np.abs(np.abs(np.sum(g.values * values, axis=1)) - 1).max() < 1e-8
            else:
                np.testing.assert_array_equal(g.values, values.astype(np.float32))
            assert g.interpolation == ("cubic_spline" if tr.interpolation == "catmull_rom"
                                       else tr.interpolation)


def test_sampled_poses_match_within_int16_rounding(tmp_path, rig, clips):
    """Between the keys too: the curves are the same (CUBICSPLINE keeps Catmull-Rom's
    tangents), rotations within the int16 step."""
    out = tmp_path / "c.gltf"
    save_gltf_compressed(rig, out, clips)
    back = rigedit.load_rig(out)
    for name, clip in clips.items():
        for t in np.linspace(0, clip.duration, 37):
            a, b = clip.sample(t), back.clips[name].sample(t)
            np.testing.assert_allclose(b.translation, a.translation, atol=1e-6)
            np.testing.assert_allclose(b.scale, a.scale, atol=1e-6)
            dots = np.abs(np.sum(a.rotation * b.rotation, axis=1))
            assert np.arccos(np.minimum(dots, 1)).max() * 2 < 1e-4


def test_rotations_are_normalised_shorts_and_times_are_shared(tmp_path, rig, clips):
    out = tmp_path / "c.glb"
    save_gltf_compressed(rig, out, clips)
    g = _doc(out)
    for anim in g.animations:
        for ch in anim.channels:
            acc = g.accessors[anim.samplers[ch.sampler].output]
            if ch.target.path == "rotation" and acc.componentType == 5126:
                assert acc.count == 1           # a rest key of a channel another clip moves
            elif ch.target.path == "rotation":
                assert (acc.componentType, acc.normalized) == (5122, True)
                assert g.bufferViews[acc.bufferView].byteLength == 8 * acc.count
            else:
                assert acc.componentType == 5126
    inputs = {s.input for a in g.animations for s in a.samplers}
    distinct = {np.asarray(tr.times, np.float32).tobytes() for c in clips.values()
                for tr in c.tracks.values()}
    distinct |= {np.float32([0.0, clips["wave_reduced"].duration]).tobytes()}  # the hold key
    assert len(inputs) <= len(distinct)
    times = [tuple(g.accessors[i].max) for i in inputs]
    assert len(times) == len(inputs)
    # two samplers with the same times read the same accessor
    per_input = {}
    for a in g.animations:
        for s in a.samplers:
            per_input.setdefault(s.input, 0)
            per_input[s.input] += 1
    assert max(per_input.values()) > 1


def test_constant_tracks(tmp_path, rig, clips):
    """A one-key track at the rest is left out; another one is one key."""
    out = tmp_path / "c.glb"
    save_gltf_compressed(rig, out, clips)
    g = _doc(out)
    nodes = {n.name: i for i, n in enumerate(g.nodes)}
    anim = next(a for a in g.animations if a.name == "walk_reduced")
    scales = {g.nodes[c.target.node].name: anim.samplers[c.sampler] for c in anim.channels
              if c.target.path == "scale"}
    one = [n for (n, ch), tr in clips["walk_reduced"].tracks.items()
           if ch == "scale" and len(tr.times) == 1]
    rest_joint, scaled_joint = one
    assert rest_joint not in scales and rest_joint in nodes
    assert g.accessors[scales[scaled_joint].output].count == 1


def test_every_animation_keys_the_same_channels(tmp_path, rig):
    """A channel one clip moves gets one exact rest key in a clip that leaves it alone (a
    viewer switching animations may keep what the last one left on an unkeyed channel)."""
    sk = rig.skeleton
    moved, still = sk.names[3], sk.names[4]
    turn = [[0, 0, 0, 1], [0, 0.2588190, 0, 0.9659258]]
    clips = {"a": Clip("a", sk, {(moved, "rotation"): Track("rotation", [0, 1], turn)}),
             "b": Clip("b", sk, {(still, "rotation"): Track("rotation", [0, 1], turn)})}
    out = tmp_path / "s.glb"
    save_gltf_compressed(rig, out, clips)
    g = _doc(out)
    for anim in g.animations:
        keyed = {g.nodes[c.target.node].name for c in anim.channels}
        assert keyed == {moved, still}
    back = rigedit.load_rig(out)
    rest = sk.rest_rotation[sk.joint_index(still)]
    got = back.clips["a"].tracks[(still, "rotation")]
    assert len(got.times) == 1
    assert np.abs(got.values[0] - rest).max() < 1e-7     # float32, not the int16 grid


def test_the_duration_is_kept_for_viewers(tmp_path, rig, clips):
    """The wave clip ends 0.25 s after its last key: one sampler holds to the end."""
    out = tmp_path / "c.glb"
    save_gltf_compressed(rig, out, clips)
    g = _doc(out)
    anim = next(a for a in g.animations if a.name == "wave_reduced")
    end = max(g.accessors[s.input].max[0] for s in anim.samplers)
    assert end == pytest.approx(clips["wave_reduced"].duration, abs=1e-6)
    back = rigedit.load_rig(out).clips["wave_reduced"]
    src = clips["wave_reduced"]
    last = src.duration - 0.25
    np.testing.assert_allclose(back.sample(src.duration).translation,
                               src.sample(last).translation, atol=1e-6)


def test_nlerp_keys_are_refused_naming_the_file(tmp_path, rig):
    sk = rig.skeleton
    clip = Clip("n", sk, {(sk.names[1], "rotation"): Track(
        "rotation", [0, 1], [[0, 0, 0, 1], [0, 0.3826834, 0, 0.9238795]], "nlerp")})
    out = tmp_path / "n.glb"
    with pytest.raises(RigFileError, match="n.glb.*nlerp"):
        save_gltf_compressed(rig, out, {"n": clip})
    assert not out.exists() and list(tmp_path.iterdir()) == []


def _views(path):
    """(JSON document, list of each buffer view's bytes as stored) of a GLB."""
    raw = path.read_bytes()
    jlen = struct.unpack_from("<I", raw, 12)[0]
    doc = json.loads(raw[20:20 + jlen])
    blob = raw[20 + jlen + 8:]
    return doc, blob


def _canonical(data, size):
    """Triangle indices with each triangle rotated to start at its smallest index (the same
    triangles, the same winding)."""
    tri = np.frombuffer(data, {2: "<u2", 4: "<u4"}[size]).reshape(-1, 3)
    first = np.argmin(tri, axis=1)
    return np.stack([tri[np.arange(len(tri)), (first + k) % 3] for k in range(3)], 1).tobytes()


@pytest.mark.skipif(not meshopt_available(), reason="the meshopt package is not installed")
def test_meshopt_views_decode_to_the_plain_files_bytes(tmp_path, rig, clips):
    import meshopt

    plain = save_gltf_compressed(rig, tmp_path / "p.glb", clips).bytes_by_clip()
    packed = save_gltf_compressed(rig, tmp_path / "m.glb", clips, meshopt=True).bytes_by_clip()
    plain_doc, plain_blob = _views(tmp_path / "p.glb")
    doc, blob = _views(tmp_path / "m.glb")
    assert sum(sum(k.values()) for k in packed.values()) < \
        sum(sum(k.values()) for k in plain.values())
    assert doc["extensionsRequired"] == [MESHOPT]
    assert doc["buffers"][1]["extensions"][MESHOPT] == {"fallback": True}
    assert len(doc["bufferViews"]) == len(plain_doc["bufferViews"])
    compressed = 0
    for view, plain in zip(doc["bufferViews"], plain_doc["bufferViews"]):
        want = plain_blob[plain["byteOffset"]:plain["byteOffset"] + plain["byteLength"]]
        ext = view.get("extensions", {}).get(MESHOPT)
        if ext is None:
            got = blob[view["byteOffset"]:view["byteOffset"] + view["byteLength"]]
        else:
            compressed += 1
            assert view["buffer"] == 1 and ext["buffer"] == 0
            packed = blob[ext["byteOffset"]:ext["byteOffset"] + ext["byteLength"]]
            rows = meshopt.decode_gltf_buffer(packed, ext["count"], ext["byteStride"],
                                              ext["mode"])
            got = np.asarray(rows).tobytes()
            if ext["mode"] == "TRIANGLES":   # the index codec may rotate a triangle's corners
                got, want = (_canonical(b, ext["byteStride"]) for b in (got, want))
        assert got == want
    assert compressed >= len(doc["bufferViews"]) // 2
    assert (tmp_path / "m.glb").stat().st_size < 0.8 * (tmp_path / "p.glb").stat().st_size
