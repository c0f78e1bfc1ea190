"""The glTF and BVH readers hold the trust promise (issue 19, section 4): each failure shape
the held-back corpus found is one RigFileError naming the file, never another exception, an
allocation from a file's claim, a read outside the file's folder, a device or a FIFO."""
import json
import os
import resource
import signal
import warnings

import numpy as np
import pytest

import rigedit
from gltf_builder import two_bone
from rigedit.errors import RigFileError
from rigedit.io.gltf_data import GltfData


def _load(path, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rigedit.load_rig(path, **kwargs)


def _refused(path, match, **kwargs):
    with pytest.raises(RigFileError, match=match) as err:
        _load(path, **kwargs)
    message = str(err.value)
    assert message.startswith(str(path)) and "\n" not in message, message
    return message


def _gltf(tmp_path, mutate=None, container="embedded", name="bad"):
    b, _ = two_bone()
    if mutate is not None:
        mutate(b.doc)
    return b.write(tmp_path / f"{name}.{'glb' if container == 'glb' else 'gltf'}", container)


@pytest.fixture
def memory_cap():
    """Address space capped at 4 GiB for the test: an allocation from a file's claim fails
    with MemoryError instead of swapping the machine."""
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = 4 * 2**30
    resource.setrlimit(resource.RLIMIT_AS, (cap if hard < 0 or hard > cap else hard, hard))
    yield
    resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


@pytest.fixture
def deadline():
    """A read that blocks (a FIFO opened without O_NONBLOCK) fails the test after 20 s."""
    def expire(signum, frame):
        raise TimeoutError("the read blocked")
    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(20)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


# ---------------------------------------------------------------------------- glTF: JSON
@pytest.mark.parametrize("container", ["embedded", "glb"])
def test_gltf_extras_nested_thousands_deep(tmp_path, container):
    deep = "[" * 5000 + "1" + "]" * 5000
    path = _gltf(tmp_path, lambda d: d["nodes"][0].update(extras="DEEP"), "embedded")
    text = path.read_text().replace('"DEEP"', deep)
    if container == "glb":
        import struct
        body = text.encode() + b" " * (-len(text) % 4)
        chunk = struct.pack("<II", len(body), 0x4E4F534A) + body
        path = tmp_path / "bad.glb"
        path.write_bytes(b"glTF" + struct.pack("<II", 2, 12 + len(chunk)) + chunk)
    else:
        path.write_text(text)
    _refused(path, "nest")


def test_gltf_extras_nested_past_the_bound_that_json_parses(tmp_path):
    deep = "[" * 500 + "]" * 500   # json parses this; what walks it next might not
    path = _gltf(tmp_path, lambda d: d["nodes"][0].update(extras="DEEP"))
    path.write_text(path.read_text().replace('"DEEP"', deep))
    _refused(path, "nested at most 100 levels")


def test_gltf_node_children_ten_thousand_deep_load(tmp_path):
    def chain(doc):
        n0 = len(doc["nodes"])
        doc["nodes"] += [{"name": f"n{i}", "children": [n0 + i + 1]} for i in range(9999)]
        doc["nodes"].append({"name": "last"})
    rig = _load(_gltf(tmp_path, chain))
    assert len(rig.vertices) == 8


# ---------------------------------------------------------------------------- glTF: claims
def _zero_filled(doc, count, kind="VEC3", use="POSITION"):
    doc["accessors"].append({"componentType": 5126, "count": count, "type": kind})
    index = len(doc["accessors"]) - 1
    if use == "POSITION":
        doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = index
    else:
        doc["skins"][0]["inverseBindMatrices"] = index


@pytest.mark.parametrize("use,kind", [("POSITION", "VEC3"), ("ibm", "MAT4")])
def test_gltf_zero_filled_accessor_count_is_a_bounded_claim(tmp_path, memory_cap, use, kind):
    path = _gltf(tmp_path, lambda d: _zero_filled(d, 2**40, kind, use))
    _refused(path, "without a bufferView of at most")


def test_gltf_zero_filled_accessor_of_a_plausible_count_still_reads(tmp_path):
    path = _gltf(tmp_path)
    data = GltfData(path)
    data.gltf.accessors.append(type(data.gltf.accessors[0])(componentType=5126, count=1000,
                                                            type="VEC3"))
    out = data.accessor(len(data.gltf.accessors) - 1)
    assert out.shape == (1000, 3) and not out.any()


def test_gltf_sparse_count_beyond_its_bytes_is_refused(tmp_path, memory_cap):
    def sparse(doc):
        b_pos = doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
        view = doc["accessors"][b_pos]["bufferView"]
        doc["accessors"][b_pos]["sparse"] = {
            "count": 2**31, "indices": {"bufferView": view, "componentType": 5125},
            "values": {"bufferView": view}}
    _refused(_gltf(tmp_path, sparse), "sparse")


# ---------------------------------------------------------------------------- glTF: URIs
def _external(tmp_path, uri, image=False):
    path = _gltf(tmp_path, container="external", name="char")
    doc = json.loads(path.read_text())
    if image:
        doc["images"] = [{"uri": uri}]
        doc["textures"] = [{"source": 0}]
        doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
        doc["meshes"][0]["primitives"][0]["material"] = 0
    else:
        doc["buffers"][0]["uri"] = uri
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize("uri", ["/etc/passwd", "../../../../../../../../etc/passwd",
                                 "file:///etc/passwd", "%2Fetc%2Fpasswd",
                                 "../../../../../../../../dev/zero", "/dev/urandom"])
def test_gltf_buffer_uri_outside_the_folder_is_refused(tmp_path, memory_cap, uri):
    message = _refused(_external(tmp_path, uri), "allow it with --allow-outside-uris")
    assert "buffer 0" in message


def test_gltf_image_uri_outside_the_folder_is_refused(tmp_path):
    _refused(_external(tmp_path, "/etc/passwd", image=True), "image 0: expected a uri inside")


def test_gltf_symlink_out_of_the_folder_is_refused(tmp_path):
    path = _gltf(tmp_path, container="external", name="char")
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    own = tmp_path / "char data.bin"
    os.replace(own, outside / "data.bin")
    sub = tmp_path / "sub"
    sub.mkdir()
    moved = sub / path.name
    os.replace(path, moved)
    (sub / own.name).symlink_to(outside / "data.bin")
    _refused(moved, "expected a uri inside the file's folder")


def test_gltf_uri_climbing_and_coming_back_in_is_read(tmp_path):
    folder = tmp_path / "assets"
    folder.mkdir()
    path = _gltf(folder, container="external", name="char")
    doc = json.loads(path.read_text())
    doc["buffers"][0]["uri"] = "../assets/char%20data.bin"
    path.write_text(json.dumps(doc))
    assert len(_load(path).vertices) == 8


def test_gltf_outside_uri_reads_when_allowed(tmp_path):
    folder = tmp_path / "f"
    folder.mkdir()
    path = _gltf(folder, container="external", name="char")
    doc = json.loads(path.read_text())
    doc["buffers"][0]["uri"] = str(folder / "char data.bin")   # absolute
    path.write_text(json.dumps(doc))
    _refused(path, "--allow-outside-uris")
    data = GltfData(path, allow_outside_uris=True)
    assert len(data.buffer(0)) == doc["buffers"][0]["byteLength"]


@pytest.mark.parametrize("kind", ["fifo", "dev"])
def test_gltf_uri_to_a_fifo_or_device_never_blocks(tmp_path, memory_cap, deadline, kind):
    path = _gltf(tmp_path, container="external", name="char")
    target = tmp_path / "char data.bin"
    target.unlink()
    if kind == "fifo":
        os.mkfifo(target)
        problem = "FIFO"
    else:
        target.symlink_to("/dev/zero")   # inside the folder by name, a device by nature
        problem = "expected a uri inside|character device"
    data = GltfData(path, allow_outside_uris=True)   # even when outside uris are allowed
    with pytest.raises(RigFileError, match=problem):
        data.buffer(0)
    _refused(path, problem)


def test_gltf_other_schemes_are_never_fetched(tmp_path):
    _refused(_external(tmp_path, "https://example.com/x.bin"), "rigedit fetches nothing")


# ---------------------------------------------------------------------------- glTF: values
def _joint(doc, **fields):
    node = doc["nodes"][doc["skins"][0]["joints"][1]]
    for key in ("translation", "rotation", "scale"):
        if "matrix" in fields:
            node.pop(key, None)
    node.update(fields)


@pytest.mark.parametrize("fields,match", [
    ({"scale": [0, 0, 0]}, "joint scale without zeros"),
    ({"scale": [1, 0, 1]}, "joint scale without zeros"),
    ({"matrix": [0] * 16}, "invertible joint matrix"),
    ({"matrix": [1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}, "invertible joint matrix"),
])
def test_gltf_zero_scale_or_matrix_is_one_line(tmp_path, fields, match):
    _refused(_gltf(tmp_path, lambda d: _joint(d, **fields)), match)


def _attribute(doc, name="POSITION", **fields):
    index = doc["meshes"][0]["primitives"][0]["attributes"][name]
    doc["accessors"][index].update(fields)


@pytest.mark.parametrize("name,fields", [
    ("POSITION", {"componentType": 5125}),               # UNSIGNED_INT
    ("POSITION", {"type": "VEC4"}),
    ("NORMAL", {"componentType": 5121}),                  # unsigned bytes: not a direction
    ("JOINTS_0", {"componentType": 5126}),                # float joint indices
    ("WEIGHTS_0", {"componentType": 5125}),
])
def test_gltf_component_types_the_spec_does_not_allow(tmp_path, name, fields):
    _refused(_gltf(tmp_path, lambda d: _attribute(d, name, **fields)), f"{name}: expected")


@pytest.mark.parametrize("material,match", [(-1, "got -1"), (5, "got 5"), (True, "got True"),
                                            (0.5, "got 0.5")])
def test_gltf_material_index_out_of_range(tmp_path, material, match):
    def mutate(doc):
        doc["materials"] = [{"name": "only"}]
        doc["meshes"][0]["primitives"][0]["material"] = material
    _refused(_gltf(tmp_path, mutate), f"material index 0..0, {match}")


def test_gltf_valid_material_index_loads(tmp_path):
    def mutate(doc):
        doc["materials"] = [{"name": "only"}]
        doc["meshes"][0]["primitives"][0]["material"] = 0
    assert len(_load(_gltf(tmp_path, mutate)).vertices) == 8


# ---------------------------------------------------------------------------- BVH
def _bvh(frames="2", frame_time="0.033", count="3", depth=0, offset="0 10 0",
         values="0 90 0 1 2 3", lines=2):
    text = ["HIERARCHY", "ROOT hips", "{", " OFFSET 0 0 0",
            " CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
            " JOINT a", " {", f"  OFFSET {offset}", f"  CHANNELS {count} Zrotation Xrotation "
            "Yrotation"]
    for i in range(depth):
        text += [f"JOINT d{i}", "{", "OFFSET 0 1 0"]
    text += ["End Site", "{", "OFFSET 0 10 0", "}"] + ["}"] * depth + [" }", "}", "MOTION",
                                                                        f"Frames: {frames}",
                                                                        f"Frame Time: {frame_time}"]
    text += [f"0 {values}"[2:] + " 0 0 0"] * lines
    return "\n".join(text) + "\n"


def _write(tmp_path, text, name="bad.bvh"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_bvh_base_file_loads(tmp_path):
    rig = _load(_write(tmp_path, _bvh()), scale=0.01)
    assert rig.skeleton.names == ["hips", "a"] and rig.clips["take"].duration == \
        pytest.approx(0.033)


def test_bvh_frames_zero_is_a_skeleton_without_a_clip(tmp_path):
    path = _write(tmp_path, _bvh(frames="0", lines=0))
    rig = _load(path, scale=0.01)
    assert rig.skeleton.names == ["hips", "a"] and rig.clips == {}
    out = tmp_path / "out.bvh"
    rigedit.save_rig(rig, out)
    assert _load(out, scale=0.01).skeleton.names == ["hips", "a"]


@pytest.mark.parametrize("frames", ["inf", "nan", "-1", "2.0", "1e300", "²", "３", "0x2", ""])
def test_bvh_frame_count_in_ascii_digits_only(tmp_path, frames):
    _refused(_write(tmp_path, _bvh(frames=frames)), "Frames:")


@pytest.mark.parametrize("count", ["³", "٣", "３", "3.0", "-3", "+3"])
def test_bvh_channel_count_in_ascii_digits_only(tmp_path, count):
    _refused(_write(tmp_path, _bvh(count=count)), "channel count")


def test_bvh_hierarchy_ten_thousand_deep_is_one_line(tmp_path):
    _refused(_write(tmp_path, _bvh(depth=10000)), "nested at most 1000 deep")


def test_bvh_hierarchy_nine_hundred_deep_loads_and_exports(tmp_path):
    rig = _load(_write(tmp_path, _bvh(depth=900)), scale=0.01)
    assert len(rig.skeleton.names) == 902
    out = tmp_path / "out.bvh"
    rigedit.save_rig(rig, out)    # the writer walks the chain without recursion
    assert len(_load(out, scale=0.01).skeleton.names) == 902


@pytest.mark.parametrize("kind", ["offset", "position", "angle"])
def test_bvh_values_that_would_overflow_skinning_are_refused(tmp_path, kind):
    text = {"offset": _bvh(offset="1e30 0 0"), "position": _bvh(values="1e30 90 0 1 2 3"),
            "angle": _bvh(values="0 90 0 1 2 1e300")}[kind]
    assert text != _bvh()
    _refused(_write(tmp_path, text), r"within \+-1e\+09")


def test_bvh_lengths_beyond_a_thousand_kilometres_are_refused(tmp_path):
    path = _write(tmp_path, _bvh(offset="5e8 0 0"))
    _refused(path, "expected lengths within 1e[+]06 m, got 5e[+]08 m", scale=1.0)
    assert len(_load(path, scale=0.001).skeleton.names) == 2   # in millimetres: 500 km


@pytest.mark.parametrize("unit", ["cm", "mm"])
def test_bvh_large_accepted_values_export_and_load_back(tmp_path, unit):
    scale = {"cm": 0.01, "mm": 0.001}[unit]
    rig = _load(_write(tmp_path, _bvh(offset="9e7 0 0")), scale=scale)   # 900 or 90 km
    out = tmp_path / "out.bvh"
    rigedit.save_rig(rig, out)    # centimetres
    back = _load(out, scale=0.01)
    assert np.allclose(back.skeleton.rest_translation, rig.skeleton.rest_translation,
                       rtol=1e-6)
    assert np.all(np.isfinite(back.skin(back.rest_pose())))


@pytest.mark.parametrize("frame_time", ["0", "-1", "inf", "nan", "1e300"])
def test_bvh_frame_time(tmp_path, frame_time):
    _refused(_write(tmp_path, _bvh(frame_time=frame_time)), "Frame Time")


@pytest.mark.parametrize("value", [1e30, 3e38, float("inf"), float("nan")])
def test_gltf_positions_so_large_skinning_overflows_are_refused(tmp_path, value):
    b, _ = two_bone()
    index = b.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
    view = b.doc["bufferViews"][b.doc["accessors"][index]["bufferView"]]
    start = view["byteOffset"]
    b.bin[start:start + 4] = np.float32(value).tobytes()
    path = b.write(tmp_path / "big.glb")
    _refused(path, "finite")


def test_gltf_large_positions_that_fit_export_and_load_back(tmp_path):
    b, _ = two_bone()
    index = b.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
    view = b.doc["bufferViews"][b.doc["accessors"][index]["bufferView"]]
    b.bin[view["byteOffset"]:view["byteOffset"] + 4] = np.float32(5e8).tobytes()
    rig = _load(b.write(tmp_path / "big.glb"))
    for out in (tmp_path / "out.glb", tmp_path / "folder"):
        rigedit.save_rig(rig, out)
        back = _load(out)
        assert np.allclose(back.vertices, rig.vertices, rtol=1e-6)
