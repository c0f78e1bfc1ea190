"""glTF out: round trips, the structural rules of the spec, and the Khronos validator."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pygltflib
import pytest

import rigedit
from rigedit.animation.clip import Clip, Track
from rigedit.errors import RigFileError
from rigedit.io.gltf_read import load_gltf
from rigedit.io.gltf_write import save_gltf
from test_gltf import SAMPLES, sample_path

BUNDLED = ["humanoid", "quadruped"]


def _load(source):
    return rigedit.load_rig(source) if source in BUNDLED else load_gltf(sample_path(source))


def _rel(a, b):
    """Largest difference divided by the largest magnitude (1 at least)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.abs(a - b).max(initial=0) / max(1.0, np.abs(a).max(initial=0)))


def _times(clip, fps=30.0):
    return np.unique(np.r_[clip.key_times(), np.arange(0, clip.duration + 1e-9, 1 / fps)])


def assert_same_rig(a, b, tol=1e-6, skins=3):
    assert a.skeleton.names == b.skeleton.names
    assert np.array_equal(a.skeleton.parents, b.skeleton.parents)
    assert np.array_equal(a.skeleton.deform, b.skeleton.deform)
    np.testing.assert_allclose(a.skeleton.tails, b.skeleton.tails, atol=1e-12)
    assert _rel(a.vertices, b.vertices) < tol
    assert np.array_equal(a.faces, b.faces)
    assert _rel(a.binding.dense(), b.binding.dense()) < tol
    assert _rel(a.skeleton.inverse_bind_matrices, b.skeleton.inverse_bind_matrices) < tol
    assert list(a.clips) == list(b.clips)
    for name, ca in a.clips.items():
        cb = b.clips[name]
        assert cb.duration == pytest.approx(ca.duration, abs=1e-6) and cb.loop == ca.loop
        times = _times(ca)
        for i, t in enumerate(times):
            pa, pb = ca.sample(t), cb.sample(t)
            assert _rel(pa.translation, pb.translation) < tol
            assert np.abs(np.abs(np.sum(pa.rotation * pb.rotation, axis=1)) - 1).max() < tol
            assert _rel(pa.scale, pb.scale) < tol
            if i % max(1, len(times) // skins) == 0 and len(a.vertices):
                assert _rel(a.skin(pa), b.skin(pb)) < 10 * tol


@pytest.mark.parametrize("source", SAMPLES + BUNDLED)
def test_round_trip(tmp_path, source):
    rig = _load(source)
    out = save_gltf(rig, tmp_path / "out.glb")
    back = load_gltf(out)
    assert_same_rig(rig, back)
    if rig.surface is not None:
        if rig.surface.normals is not None:
            np.testing.assert_allclose(back.surface.normals, rig.surface.normals, atol=1e-6)
        if rig.surface.uvs is not None:
            np.testing.assert_allclose(back.surface.uvs, rig.surface.uvs, atol=1e-6)
        for ma, mb in zip(rig.surface.materials, back.surface.materials):
            np.testing.assert_allclose(mb.base_color, ma.base_color, atol=1e-7)
            assert (ma.texture is None) == (mb.texture is None)
            if ma.texture is not None:
                assert mb.image_bytes == ma.image_bytes and np.array_equal(mb.texture, ma.texture)
    check_structure(out)


def test_gltf_json_with_embedded_buffer(tmp_path):
    rig = _load("CesiumMan.glb")
    out = save_gltf(rig, tmp_path / "out.gltf", clips=[])
    assert json.loads(out.read_text())["buffers"][0]["uri"].startswith("data:")
    back = load_gltf(out)
    assert back.clips == {} and _rel(back.vertices, rig.vertices) < 1e-6
    check_structure(out)


def _mode_clip(rig):
    """A clip on the humanoid with one track per interpolation mode."""
    sk = rig.skeleton
    times = np.array([0.0, 0.4, 0.9, 1.5])
    rng = np.random.default_rng(3)
    tracks = {}
    from scipy.spatial.transform import Rotation
    modes = ["step", "nlerp", "slerp", "hybrid", "catmull_rom", "cubic_spline"]
    for k, mode in enumerate(modes):
        q = Rotation.from_rotvec(rng.normal(0, 0.8, (4, 3))).as_quat()
        tan = rng.normal(0, 0.3, (4, 2, 4)) if mode == "cubic_spline" else None
        tracks[(sk.names[k + 1], "rotation")] = Track("rotation", times, q, mode, tan)
    for k, mode in enumerate(["step", "linear", "catmull_rom", "cubic_spline"]):
        v = rng.normal(0, 0.1, (4, 3)) + sk.rest_translation[k + 8]
        tracks[(sk.names[k + 8], "translation")] = Track("translation", times, v, mode)
    return Clip("modes", sk, tracks, duration=2.0, loop=False)


def test_interpolation_modes_map_honestly(tmp_path):
    rig = rigedit.load_rig("humanoid")
    rig.clips = {"modes": _mode_clip(rig)}
    back = load_gltf(save_gltf(rig, tmp_path / "m.glb"))
    clip, got = rig.clips["modes"], back.clips["modes"]
    want = {"step": "step", "linear": "linear", "slerp": "slerp", "catmull_rom": "cubic_spline",
            "cubic_spline": "cubic_spline", "nlerp": "slerp", "hybrid": "slerp"}
    worst = {}
    for key, tr in clip.tracks.items():
        assert got.tracks[key].interpolation == want[tr.interpolation]
        errs = []
        for t in np.linspace(0, 1.6, 321):
            a, b = tr.sample(t), got.tracks[key].sample(t)
            if tr.channel == "rotation":
                errs.append(2 * np.arccos(min(1.0, abs(float(np.dot(a, b))))))
            else:
                errs.append(np.abs(a - b).max())
        worst[tr.interpolation, tr.channel] = max(errs)
    for (mode, channel), err in worst.items():
        # nlerp/hybrid are resampled (glTF has no nlerp): within 1e-5 rad; the rest exact
        assert err < (1e-5 if mode in ("nlerp", "hybrid") else 2e-6), (mode, channel, err)
    assert got.duration == 2.0 and got.loop is False


def test_export_refuses_unknown_clip_and_extension(tmp_path):
    rig = _load("SimpleSkin.gltf")
    with pytest.raises(RigFileError, match="unknown clip 'nope'"):
        save_gltf(rig, tmp_path / "a.glb", clips=["nope"])
    with pytest.raises(RigFileError, match="expected a .glb or .gltf"):
        save_gltf(rig, tmp_path / "a.obj")
    assert not list(tmp_path.iterdir())          # nothing half-written


# ---------------------------------------------------------------------- structure / validator
def check_structure(path):
    """The rules of the spec the Khronos validator checks most often, read with pygltflib."""
    g = pygltflib.GLTF2().load(str(path))
    blob = g.binary_blob() if str(path).endswith(".glb") else None
    for view in g.bufferViews:
        assert (view.byteOffset or 0) % 4 == 0
    vertex_views = set()
    for mesh in g.meshes:
        for prim in mesh.primitives:
            at = prim.attributes
            pos = g.accessors[at.POSITION]
            assert pos.min is not None and pos.max is not None
            for name, idx in vars(at).items():
                if idx is not None:
                    vertex_views.add(g.accessors[idx].bufferView)
            for s in range(2):
                j = getattr(at, f"JOINTS_{s}", None)
                if j is None:
                    continue
                assert g.accessors[j].componentType in (5121, 5123)
                w = g.accessors[getattr(at, f"WEIGHTS_{s}")]
                assert w.componentType == 5126
    for v in vertex_views:
        stride = g.bufferViews[v].byteStride
        assert stride is not None and stride % 4 == 0
    for skin in g.skins:
        assert g.accessors[skin.inverseBindMatrices].count == len(skin.joints)
    for anim in g.animations:
        for smp in anim.samplers:
            acc = g.accessors[smp.input]
            assert acc.min is not None and acc.max is not None
            if blob is not None:
                bv = g.bufferViews[acc.bufferView]
                t = np.frombuffer(blob, "<f4", acc.count, bv.byteOffset + (acc.byteOffset or 0))
                assert np.all(np.diff(t) > 0)
                assert t[0] == pytest.approx(acc.min[0]) and t[-1] == pytest.approx(acc.max[0])
    if blob is not None:  # weights of every primitive sum to 1
        for mesh in g.meshes:
            for prim in mesh.primitives:
                total = 0
                for s in range(2):
                    idx = getattr(prim.attributes, f"WEIGHTS_{s}", None)
                    if idx is not None:
                        acc = g.accessors[idx]
                        bv = g.bufferViews[acc.bufferView]
                        total = total + np.frombuffer(blob, "<f4", acc.count * 4, bv.byteOffset
                                                      ).reshape(-1, 4).sum(axis=1)
                assert np.abs(total - 1).max() < 1e-6


def _validator():
    script = os.environ.get("RIGEDIT_GLTF_VALIDATOR")
    if not script or not Path(script).is_file() or shutil.which("node") is None:
        pytest.skip("set RIGEDIT_GLTF_VALIDATOR to a node script running the gltf-validator "
                    "npm package (see the README); the structural checks run without it")
    return script


@pytest.mark.parametrize("source", SAMPLES + BUNDLED)
@pytest.mark.parametrize("ext", [".glb", ".gltf"])
def test_khronos_validator_finds_nothing(tmp_path, source, ext):
    script = _validator()
    rig = _load(source)
    if source == "humanoid":
        rig.clips["modes"] = _mode_clip(rig)
    out = save_gltf(rig, tmp_path / f"out{ext}")
    run = subprocess.run(["node", script, str(out)], capture_output=True, text=True, timeout=120)
    report = json.loads(run.stdout)
    issues = report["issues"]
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"][:5]
    assert report["info"]["animationCount"] == len(rig.clips)


def test_eight_influences_and_several_primitives(tmp_path):
    """JOINTS_1/WEIGHTS_1 and two primitives with two materials survive a round trip."""
    from gltf_builder import two_bone

    b, _ = two_bone(two_sets=True)
    prim = b.doc["meshes"][0]["primitives"][0]
    second = json.loads(json.dumps(prim))
    second["material"] = 1
    prim["material"] = 0
    b.doc["meshes"][0]["primitives"].append(second)
    b.doc["materials"] = [{"name": "red", "pbrMetallicRoughness": {"baseColorFactor":
                                                                  [1, 0, 0, 1]}},
                          {"name": "blue", "pbrMetallicRoughness": {"baseColorFactor":
                                                                   [0, 0, 1, 0.5]}}]
    rig = load_gltf(b.write(tmp_path / "in.glb"))
    assert len(rig.vertices) == 16 and list(rig.surface.primitive_material) == [0, 1]
    assert np.array_equal(rig.surface.vertex_primitive, np.repeat([0, 1], 8))
    out = save_gltf(rig, tmp_path / "out.glb")
    g = pygltflib.GLTF2().load(str(out))
    assert [p.material for p in g.meshes[0].primitives] == [0, 1]
    back = load_gltf(out)
    assert_same_rig(rig, back)
    np.testing.assert_allclose(back.surface.materials[1].base_color, [0, 0, 1, 0.5])
    check_structure(out)
    if os.environ.get("RIGEDIT_GLTF_VALIDATOR") and shutil.which("node"):
        run = subprocess.run(["node", os.environ["RIGEDIT_GLTF_VALIDATOR"], str(out)],
                             capture_output=True, text=True, timeout=120)
        issues = json.loads(run.stdout)["issues"]
        assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"][:5]


def test_six_distinct_influences_write_two_sets(tmp_path):
    rig = rigedit.load_rig("humanoid")
    rng = np.random.default_rng(0)
    v, j = len(rig.vertices), len(rig.skeleton)
    idx = np.argsort(rng.random((v, j)), axis=1)[:, :6]
    rig.bind(idx, rng.random((v, 6)) + 0.01)
    rig.clips = {"walk": rig.clips["walk"]}
    out = save_gltf(rig, tmp_path / "six.glb")
    g = pygltflib.GLTF2().load(str(out))
    assert g.meshes[0].primitives[0].attributes.JOINTS_1 is not None
    back = load_gltf(out)
    assert_same_rig(rig, back)
    check_structure(out)


@pytest.mark.parametrize("duration", [1.5, 0.0])
def test_a_clip_of_no_tracks_is_kept_with_its_length(tmp_path, duration):
    rig = rigedit.load_rig("humanoid")
    rig.clips["still"] = Clip("still", rig.skeleton, {}, duration, False)
    out = save_gltf(rig, tmp_path / "out.glb")
    back = rigedit.load_rig(out)
    assert sorted(back.clips) == sorted(rig.clips)
    still = back.clips["still"]
    assert still.duration == pytest.approx(duration)
    pose = still.sample(0.5 * duration)
    np.testing.assert_allclose(pose.as_array(), back.rest_pose().as_array(), atol=1e-6)
    if os.environ.get("RIGEDIT_GLTF_VALIDATOR"):
        run = subprocess.run(["node", _validator(), str(out)], capture_output=True, text=True,
                             timeout=120)
        assert json.loads(run.stdout)["issues"]["numErrors"] == 0
