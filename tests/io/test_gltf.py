"""glTF in: rigedit's skinning of glTF files against an independent reading of the spec."""
from __future__ import annotations

from testpaths import REPO
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from gltf_builder import two_bone
from gltf_reference import Reference
from rigedit.errors import RigFileError
from rigedit.io.gltf_read import GltfWarning, load_gltf, unique_names

DATA = REPO.parent / "shared" / "data" / "khronos-gltf"
SAMPLES = ["CesiumMan.glb", "RiggedFigure.glb", "RiggedSimple.glb", "SimpleSkin.gltf"]


def sample_path(name):
    path = DATA / name
    if not path.is_file():
        pytest.skip(f"shared data not present: {path}")
    return path


def worst_error(path, rig, fps=30.0):
    """Largest distance between rigedit's and the reference's skinned vertices over the key
    times and a 30 fps grid of every clip, divided by the bounding-box diagonal."""
    ref = Reference(path)
    rest = ref.skinned()
    diag = float(np.linalg.norm(np.ptp(rest, axis=0)))
    worst = float(np.abs(ref.skinned() - rig.skin(rig.rest_pose())).max())
    assert len(rig.clips) == len(ref.g.animations or [])
    for a, clip in enumerate(rig.clips.values()):
        grid = np.arange(0.0, clip.duration + 1e-9, 1.0 / fps)
        for t in sorted(set(ref.key_times(a)) | set(grid.tolist())):
            got = rig.skin(clip.sample(t))
            worst = max(worst, float(np.abs(ref.skinned(a, t) - got).max()))
    return worst / diag


@pytest.mark.parametrize("name", SAMPLES)
def test_khronos_sample_skins_like_the_spec(name):
    path = sample_path(name)
    rig = load_gltf(path)
    assert worst_error(path, rig) < 1e-5


def test_cesium_man_reads_its_surface_and_bind_matrices():
    path = sample_path("CesiumMan.glb")
    rig = load_gltf(path)
    ref = Reference(path)
    skin = ref.g.skins[0]
    assert rig.skeleton.names[0] == "Skeleton_torso_joint_1"
    assert np.all(rig.skeleton.parents < np.arange(len(rig.skeleton)))
    ibm = np.array(ref.accessor(skin.inverseBindMatrices)).reshape(-1, 4, 4).transpose(0, 2, 1)
    for i, node in enumerate(skin.joints):
        j = rig.skeleton.index[ref.g.nodes[node].name]
        assert np.array_equal(rig.skeleton.inverse_bind_matrices[j], ibm[i])
    surf = rig.surface
    assert surf.uvs.shape == (len(rig.vertices), 2) and surf.normals.shape == rig.vertices.shape
    mat = surf.materials[surf.textured_material()]
    assert mat.texture.shape == (1024, 1024, 4) and mat.mime == "image/jpeg"
    assert mat.texture[..., :3].std() > 10       # a real picture, not a flat fill
    assert np.all(surf.vertex_primitive == 0) and list(surf.primitive_material) == [0]


FEATURES = [
    dict(),
    dict(layout="interleaved"),
    dict(layout="interleaved", normals="byte", positions="quantized"),
    dict(sparse=True),
    dict(sparse=True, positions="quantized"),
    dict(weights="ubyte"),
    dict(weights="ushort", normals="byte"),
    dict(two_sets=True),
    dict(mode=5),
    dict(mode=6),
    dict(interpolation="STEP"),
    dict(interpolation="CUBICSPLINE"),
    dict(ancestor={"rotation": [0.0, 0.0, 0.3826834, 0.9238795], "scale": [2, 2, 2],
                   "translation": [1, 2, 3]}),
]


@pytest.mark.parametrize("container", ["glb", "embedded", "external"])
@pytest.mark.parametrize("options", FEATURES, ids=lambda o: "-".join(
    f"{k}={v if not isinstance(v, dict) else 'node'}" for k, v in o.items()) or "plain")
def test_accessor_features(tmp_path, options, container):
    builder, expected = two_bone(**options)
    path = builder.write(tmp_path / ("bar.glb" if container == "glb" else "bar.gltf"), container)
    rig = load_gltf(path)
    scale = 1000.0 if options.get("positions") == "quantized" else 1.0
    np.testing.assert_allclose(rig.vertices, expected["positions"] * scale, atol=1e-6)
    assert {tuple(f) for f in rig.faces} == {tuple(f) for f in expected["faces"]}
    tol = 1 / 255 if options.get("weights") == "ubyte" else 1e-4
    np.testing.assert_allclose(rig.binding.dense(), expected["weights"], atol=tol)
    np.testing.assert_allclose(rig.surface.normals, np.tile([0, 0, 1.0], (8, 1)), atol=1e-6)
    clip = rig.clips["bend"]
    want = {"LINEAR": "slerp", "STEP": "step", "CUBICSPLINE": "cubic_spline"}
    assert clip.tracks[("tip", "rotation")].interpolation == want[
        options.get("interpolation", "LINEAR")]
    assert worst_error(path, rig, fps=60) < 1e-6


def test_folded_ancestor_keeps_animation_exact(tmp_path):
    anc = {"rotation": [0.0, 0.0, 0.3826834, 0.9238795], "scale": [2, 2, 2],
           "translation": [1, 2, 3]}
    builder, _ = two_bone(ancestor=anc)
    # animate the root joint too: its keys must go through the folded ancestor
    b = builder
    times = b.accessor(np.array([0.0, 1.0]), "float32", minmax=True)
    moves = b.accessor(np.array([[0, 0, 0], [0.5, 0, 0]]), "float32")
    anim = b.doc["animations"][0]
    anim["samplers"].append({"input": times, "output": moves})
    root = next(i for i, n in enumerate(b.doc["nodes"]) if n.get("name") == "root")
    anim["channels"].append({"sampler": 1, "target": {"node": root, "path": "translation"}})
    path = b.write(tmp_path / "a.glb")
    rig = load_gltf(path)
    assert rig.skeleton.names == ["root", "tip"]           # Armature is not a joint
    assert worst_error(path, rig, fps=60) < 1e-6


def test_non_similar_ancestor_becomes_a_non_deforming_joint(tmp_path):
    builder, _ = two_bone(ancestor={"scale": [1, 2, 3]})
    path = builder.write(tmp_path / "a.glb")
    rig = load_gltf(path)
    assert rig.skeleton.names == ["Armature", "root", "tip"]
    assert list(rig.skeleton.deform) == [False, True, True]
    assert worst_error(path, rig, fps=60) < 1e-6


def test_unnamed_and_duplicate_joint_names(tmp_path):
    path = two_bone(names=(None, None))[0].write(tmp_path / "a.glb")
    assert load_gltf(path).skeleton.names == ["joint_1", "joint_2"]
    path = two_bone(names=("bone", "bone"))[0].write(tmp_path / "b.glb")
    assert load_gltf(path).skeleton.names == ["bone", "bone.1"]
    assert unique_names(["a", "a", "a.1"]) == ["a", "a.2", "a.1"]


@pytest.mark.parametrize("raw, want", [(None, "animation_0"), ("", "animation_0"),
                                       ("run/fast", "run_fast"), ("..", "animation_0")])
def test_clip_names_are_safe(tmp_path, raw, want):
    builder, _ = two_bone(clip_name=raw)
    path = builder.write(tmp_path / "a.glb")
    assert list(load_gltf(path).clips) == [want]


def test_non_joint_and_morph_channels_warn_once(tmp_path):
    b, _ = two_bone()
    anim = b.doc["animations"][0]
    anim["channels"] += [{"sampler": 0, "target": {"node": 0, "path": "rotation"}},
                         {"sampler": 0, "target": {"node": 0, "path": "weights"}},
                         {"sampler": 0, "target": {"node": 0, "path": "weights"}}]
    # node 0's mesh has no morph targets: its weight channels have nothing to drive
    path = b.write(tmp_path / "a.glb")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rig = load_gltf(path)
    msgs = sorted(str(w.message) for w in caught if issubclass(w.category, GltfWarning))
    assert len(msgs) == 2, msgs
    for words in ("not joints", "2 morph-target weight channels on nodes without"):
        assert sum(words in m for m in msgs) == 1, (words, msgs)
    assert list(rig.clips["bend"].tracks) == [("tip", "rotation")]


def test_skin_without_mesh_gives_a_meshless_rig(tmp_path):
    b, _ = two_bone()
    del b.doc["nodes"][0]["mesh"]
    rig = load_gltf(b.write(tmp_path / "a.glb"))
    assert rig.vertices.shape == (0, 3) and rig.faces.shape == (0, 3)
    assert len(rig.skeleton) == 2 and "bend" in rig.clips


# ---------------------------------------------------------------------- bad input
def _glb_bytes(tmp_path):
    return two_bone()[0].write(tmp_path / "ok.glb").read_bytes()


def _patched(tmp_path, mutate):
    b, _ = two_bone()
    mutate(b.doc)
    return b.write(tmp_path / "bad.glb")


BAD_JSON = {
    "accessor out of range": (lambda d: d["meshes"][0]["primitives"][0]["attributes"].update(
        POSITION=99), "accessor index below"),
    "view out of range": (lambda d: d["bufferViews"][0].update(byteOffset=10 ** 6),
                          "inside buffer"),
    "accessor past its view": (lambda d: d["accessors"][0].update(count=10 ** 4),
                               "past its end"),
    "skin without joints": (lambda d: d["skins"][0].update(joints=[]), "expected joints"),
    "required extension": (lambda d: d.update(extensionsRequired=["KHR_draco_mesh_compression"]),
                           "KHR_draco_mesh_compression"),
    "NaN in node matrix": (lambda d: d["nodes"][1].update(matrix=[float("nan")] * 16),
                           "finite"),
}


@pytest.mark.parametrize("case", sorted(BAD_JSON))
def test_bad_json_gets_one_error_naming_the_file(tmp_path, case):
    mutate, words = BAD_JSON[case]
    path = _patched(tmp_path, mutate)
    with pytest.raises(RigFileError) as info:
        load_gltf(path)
    assert str(path) in str(info.value) and words in str(info.value)


def test_joint_index_beyond_the_skin(tmp_path):
    b, _ = two_bone()
    acc = b.doc["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"]
    b.doc["accessors"][acc]["bufferView"] = b.view(np.tile([5, 1, 0, 0], (8, 1)).astype(
        np.uint8).tobytes())
    with pytest.raises(RigFileError, match="below the skin's 2 joints, got 5"):
        load_gltf(b.write(tmp_path / "a.glb"))


@pytest.mark.parametrize("what", ["positions", "matrices"])
def test_nan_in_positions_or_matrices(tmp_path, what):
    b, _ = two_bone()
    if what == "positions":
        acc = b.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
        data = np.full((8, 3), np.nan, np.float32)
    else:
        acc = b.doc["skins"][0]["inverseBindMatrices"]
        data = np.full((2, 16), np.nan, np.float32)
    b.doc["accessors"][acc]["bufferView"] = b.view(data.tobytes())
    b.doc["accessors"][acc]["byteOffset"] = 0
    with pytest.raises(RigFileError, match="finite"):
        load_gltf(b.write(tmp_path / "a.glb"))


@pytest.mark.parametrize("case, patch, words", [
    ("magic", lambda r: b"gltf" + r[4:], "expected a glTF file"),
    ("version", lambda r: r[:4] + (1).to_bytes(4, "little") + r[8:], "version 2, got 1"),
    ("total length", lambda r: r[:8] + (len(r) + 4).to_bytes(4, "little") + r[12:],
     "file size"),
    ("truncated", lambda r: r[:-8], "file size"),
    ("chunk length", lambda r: r[:12] + (10 ** 6).to_bytes(4, "little") + r[16:],
     "past the end"),
])
def test_broken_glb_container(tmp_path, case, patch, words):
    path = tmp_path / "bad.glb"
    path.write_bytes(patch(_glb_bytes(tmp_path)))
    with pytest.raises(RigFileError, match=words) as info:
        load_gltf(path)
    assert str(path) in str(info.value)


def test_wrong_gltf_json_version(tmp_path):
    path = tmp_path / "a.gltf"
    path.write_text(json.dumps({"asset": {"version": "1.0"}}))
    with pytest.raises(RigFileError, match="version 2.x"):
        load_gltf(path)



def _paths(node, prefix=()):
    """Every (path, value) of a JSON tree, leaves and containers alike."""
    yield prefix, node
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _paths(v, prefix + (i,))


@pytest.mark.parametrize("kind", ["two_bone", "morphs", "skins"])
def test_every_field_with_a_wrong_value_gives_rig_file_error_or_loads(tmp_path, kind):
    """Fuzz: each field of a small skinned file (the bar; the bar with morph targets and a
    weights channel; three skins with rigid parts) replaced by a value of another kind or
    out of range; loading either works or raises one RigFileError naming the file, nothing
    else."""
    import copy

    from gltf_builder import morph_bar, two_skins_and_parts

    builder, _ = {"two_bone": lambda: two_bone(interpolation="CUBICSPLINE", sparse=True),
                  "morphs": lambda: morph_bar("CUBICSPLINE"),
                  "skins": two_skins_and_parts}[kind]()
    # the bar's run covers the accessors and buffer views; the others what they add
    focus = {"two_bone": None, "morphs": ("meshes", "animations"),
             "skins": ("nodes", "skins", "scenes")}[kind]
    base = builder.doc
    bad_values = ["x", -1, 2 ** 31, None, [], {}, 1.5, [float("nan")] * 3]
    outcomes = {"loaded": 0, "refused": 0}
    for path, _ in list(_paths(base))[1:]:
        if focus is not None and path[0] not in focus:
            continue
        for bad in bad_values:
            doc = copy.deepcopy(base)
            target = doc
            for key in path[:-1]:
                target = target[key]
            target[path[-1]] = bad
            builder.doc = doc
            out = builder.write(tmp_path / "f.glb")
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", GltfWarning)  # skipped parts are fine here
                    load_gltf(out)
                outcomes["loaded"] += 1
            except RigFileError as exc:
                assert str(out) in str(exc)
                outcomes["refused"] += 1
    assert outcomes["refused"] > 100 and outcomes["loaded"] > 10


@pytest.mark.parametrize("where", ["file", "data-uri"])
def test_texture_from_an_image_file_or_data_uri(tmp_path, where):
    import base64

    import imageio.v3 as iio

    b, _ = two_bone()
    image = np.zeros((4, 8, 3), np.uint8)
    image[:2, :, 0] = 255                      # top half red, bottom half blue
    image[2:, :, 2] = 255
    png = iio.imwrite("<bytes>", image, extension=".png")
    uri = "tex ture.png" if where == "file" else \
        "data:image/png;base64," + base64.b64encode(png).decode()
    if where == "file":
        (tmp_path / "tex ture.png").write_bytes(png)
        uri = "tex%20ture.png"
    prim = b.doc["meshes"][0]["primitives"][0]
    prim["attributes"]["TEXCOORD_0"] = b.accessor(np.tile([[0.5, 0.25]], (8, 1)), "float32")
    prim["material"] = 0
    b.doc.update(images=[{"uri": uri}], textures=[{"source": 0}],
                 materials=[{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])
    rig = load_gltf(b.write(tmp_path / "t.gltf", "embedded"))
    mat = rig.surface.materials[rig.surface.textured_material()]
    assert mat.texture.shape == (4, 8, 4) and mat.mime == "image/png" and mat.image_bytes == png
    assert tuple(mat.texture[0, 0]) == (255, 0, 0, 255) and tuple(mat.texture[3, 0]) == (0, 0, 255, 255)
    np.testing.assert_allclose(rig.surface.uvs, np.tile([[0.5, 0.25]], (8, 1)))


def test_a_skin_without_a_mesh_is_not_used(tmp_path):
    b, _ = two_bone()
    # a skin with no mesh first, then the bar's skin (now skin 1)
    b.doc["skins"].insert(0, {"joints": [2]})
    b.doc["nodes"][0]["skin"] = 1
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rig = load_gltf(b.write(tmp_path / "a.glb"))
    assert not [w for w in caught if issubclass(w.category, GltfWarning)]
    assert rig.skeleton.names == ["root", "tip"] and len(rig.vertices) == 8
    assert "skins" not in rig.meta.notes
