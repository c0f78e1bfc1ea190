"""Property-based fuzzing of every reader: a mutated file loads or raises a RigFileError that
names it, in bounded time and memory (issue 8, section 3).

Each format starts from a valid file written by rigedit's own savers (or meshio / VTK for the
meshes rigedit only reads), then hypothesis truncates it, flips, inserts and deletes bytes,
and, for JSON and npz, edits the structure: drops keys, changes types, puts in huge, tiny,
non-finite and beyond-float numbers, repeats keys, reshapes and retypes arrays, claims huge
shapes in .npy headers.

CI runs ``FUZZ_EXAMPLES`` (default 60) examples per format, derandomized so every run tries
the same inputs; ``RIGEDIT_FUZZ_EXAMPLES=2000 pytest tests/test_fuzz_io.py`` searches more.
"""
import copy
import io
import json
import os
import shutil
import time
import tracemalloc
import warnings
import zipfile

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import bad_input_corpus as corpus
from rigedit.errors import RigFileError
from rigedit.io import load_clip, load_mesh, load_rig_folder, load_skeleton, load_weights

FUZZ_EXAMPLES = int(os.environ.get("RIGEDIT_FUZZ_EXAMPLES", "60"))
#: Per load: at most 2 s of CPU time (a loop that never ends burns CPU; CPU time does not
#: count the waits of a machine shared with other jobs, which made wall-clock deadlines
#: flaky here: 3 s for loads that take 50 ms alone), 30 s of wall-clock time (a blocking
#: wait burns none), and the peak of memory traced by Python and numpy during the load.
MAX_CPU_SECONDS = 2.0
MAX_WALL_SECONDS = 30.0
MAX_PEAK_BYTES = 256 * 2**20

FUZZ = settings(max_examples=FUZZ_EXAMPLES, deadline=None, derandomize=True,
                database=None, suppress_health_check=[HealthCheck.too_slow,
                                                      HealthCheck.data_too_large])


# ---------------------------------------------------------------------------- valid files
@pytest.fixture(scope="module")
def base(tmp_path_factory):
    """Valid files of every format, and a scratch folder for the mutated ones."""
    root = tmp_path_factory.mktemp("fuzz")
    rig_dir = corpus.write_base(root / "rig", "rigedit")
    elk_dir = corpus.write_base(root / "elk", "elk")
    rig = load_rig_folder(rig_dir)
    files = {
        "obj": (rig_dir / "mesh.obj").read_bytes(),
        "skeleton": (rig_dir / "skeleton.json").read_bytes(),
        "elk_skeleton": (elk_dir / "skeleton" / "skeleton.json").read_bytes(),
        "clip": (rig_dir / "animations" / "walk.json").read_bytes(),
        "elk_clip": (elk_dir / "animations" / "walk.json").read_bytes(),
        "weights": (rig_dir / "weights.npz").read_bytes(),
        "rig_json": (rig_dir / "rig.json").read_bytes(),
    }
    for ext in ("ply", "stl", "vtk", "vtu", "vtp"):
        files[ext] = corpus.mesh_bytes(ext)
    files["ply_ascii"] = corpus.mesh_bytes("ply", binary=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        elk = load_rig_folder(elk_dir)
    scratch = root / "scratch"
    scratch.mkdir()
    for ext in ("ply", "stl", "vtk", "vtu", "vtp"):   # import the readers before timing
        load_mesh(_put(scratch / f"warm.{ext}", files[ext]))
    return {"files": files, "rig": rig, "elk": elk, "rig_dir": rig_dir, "scratch": scratch}


def _put(path, data):
    path.write_bytes(data)
    return path


# ---------------------------------------------------------------------------- mutations
NUMBERS = ["0", "-1", "1e-320", "1e308", "-1e308", "1e200", "2147483648", "9223372036854775808",
           "1" + "0" * 400, "7" * 5000, "NaN", "Infinity", "-Infinity", "1e400", "0.5"]
OTHERS = ["null", "true", "false", '""', '"x"', '"false"', '"no"', '"0"', "[]", "{}",
          '"a\\u0000b"', '"a\\nb"', "[[[[[[[[[[1]]]]]]]]]]", "[" * 3000 + "]" * 3000,
          '"' + "x" * 5000 + '"', "[1, 2]", "[0, 0, 0]", "[0, 0, 0, 0]", '{"a": 1}',
          '["j0"]', "[1e200, 1e200, 1e200]", '[NaN, 0, 0]', '["0", "0", "0"]']
RAW = NUMBERS + OTHERS


def _paths(obj, prefix=()):
    """Every location in a JSON tree, as a tuple of keys and indices."""
    yield prefix
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(obj, list):
        for i, v in enumerate(obj[:6]):   # a few entries of long lists are enough
            yield from _paths(v, prefix + (i,))


def _parent(obj, path):
    for key in path[:-1]:
        obj = obj[key]
    return obj


@st.composite
def json_mutation(draw, data):
    """Text of ``data`` (a JSON tree) after one to three structural edits."""
    obj = copy.deepcopy(data)
    raws = []
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from(list(_paths(obj))))
        op = draw(st.sampled_from(["replace", "replace", "replace", "drop", "wrap", "dup_key"]))
        if not path:
            if op == "replace":
                raws.append(draw(st.sampled_from(RAW)))
                obj = f"@@RAW{len(raws) - 1}@@"
            continue
        parent, key = _parent(obj, path), path[-1]
        if op == "replace":
            raws.append(draw(st.sampled_from(RAW)))
            parent[key] = f"@@RAW{len(raws) - 1}@@"
        elif op == "drop":
            del parent[key]
        elif op == "wrap":
            parent[key] = [parent[key]]
        elif op == "dup_key" and isinstance(parent, dict):
            raws.append(json.dumps(draw(st.sampled_from(RAW[:20]))))
            parent[f"@@DUP{len(raws) - 1}@@"] = key
    text = json.dumps(obj)
    for i, raw in enumerate(raws):
        text = text.replace(f'"@@RAW{i}@@"', raw)
        text = text.replace(f'"@@DUP{i}@@": ', "")   # the key repeated: "key": "key"
    return text.encode()


@st.composite
def byte_mutation(draw, data):
    """``data`` truncated, with bytes flipped, inserted, deleted or a block repeated."""
    out = bytearray(data)
    for _ in range(draw(st.integers(1, 4))):
        op = draw(st.sampled_from(["truncate", "flip", "flip", "insert", "delete", "repeat"]))
        pos = draw(st.integers(0, max(len(out) - 1, 0)))
        if op == "truncate":
            del out[pos:]
        elif op == "flip" and out:
            out[pos] ^= draw(st.integers(1, 255))
        elif op == "insert":
            out[pos:pos] = draw(st.binary(min_size=1, max_size=16))
        elif op == "delete":
            del out[pos:pos + draw(st.integers(1, 64))]
        elif op == "repeat":
            out[pos:pos] = out[pos:pos + draw(st.integers(1, 256))]
    return bytes(out)


def mutated(data, structured=None):
    """Byte mutations of ``data``; for JSON, structural ones too (``structured``)."""
    options = [byte_mutation(data)]
    if structured is not None:
        options += [json_mutation(structured), json_mutation(structured)]
    return st.one_of(*options)


DTYPES = ["<f8", "<f4", "<f2", "<i8", "<i4", "<u8", "|u1", "|b1", "<U3", "|S2", "<c16"]


@st.composite
def npz_mutation(draw, data):
    """A weights .npz with its arrays edited: dropped, retyped, reshaped, poisoned values,
    or a member whose .npy header claims a huge shape over too little data."""
    with np.load(io.BytesIO(data)) as f:
        arrays = {k: f[k] for k in f.files}
    raw_members = {}
    for _ in range(draw(st.integers(1, 3))):
        key = draw(st.sampled_from(sorted(arrays) + ["indices", "weights"]))
        if key not in arrays:
            continue
        a = arrays[key]
        op = draw(st.sampled_from(["drop", "dtype", "shape", "value", "empty", "claim",
                                   "rename"]))
        if op == "drop":
            del arrays[key]
        elif op == "dtype":
            try:
                with np.errstate(all="ignore"), warnings.catch_warnings():
                    warnings.simplefilter("ignore")   # casts that lose values are the point
                    arrays[key] = a.astype(draw(st.sampled_from(DTYPES)))
            except (ValueError, TypeError, OverflowError):
                pass
        elif op == "shape":
            arrays[key] = draw(st.sampled_from([a.T, a[..., None], a.reshape(-1), a[:-3],
                                                np.concatenate([a, a]), a[:, :1] if a.ndim == 2
                                                else a[:1]]))
        elif op == "value" and a.size and a.dtype.kind in "iuf":
            a = a.copy()
            flat = a.reshape(-1)
            idx = draw(st.integers(0, flat.size - 1))
            value = draw(st.sampled_from([-1, 0, 1e30, -0.5, 2**31 - 1, np.nan, np.inf, 99]))
            try:
                flat[idx] = value
            except (ValueError, OverflowError):
                pass
            arrays[key] = a
        elif op == "empty":
            arrays[key] = np.zeros((0,) + a.shape[1:], dtype=a.dtype)
        elif op == "claim":
            del arrays[key]
            hdr = io.BytesIO()
            shape = draw(st.sampled_from([(10**12, 4), (2**62,), (len(a), 10**9), (len(a), 4)]))
            np.lib.format.write_array_header_1_0(
                hdr, {"descr": a.dtype.str, "fortran_order": False, "shape": shape})
            raw_members[f"{key}.npy"] = hdr.getvalue() + a.tobytes()[:64]
        elif op == "rename":
            arrays[key + "_"] = arrays.pop(key)
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        for key, a in arrays.items():
            member = io.BytesIO()
            np.save(member, a, allow_pickle=True)
            zf.writestr(f"{key}.npy", member.getvalue())
        for name, raw in raw_members.items():
            zf.writestr(name, raw)
    return buf.getvalue()


# ---------------------------------------------------------------------------- the property
def _load_checked(path, load):
    """Run ``load(path)``: it returns, or raises a RigFileError naming ``path``; memory
    traced during the load stays under the bound."""
    tracemalloc.start()
    t0, cpu0 = time.perf_counter(), time.process_time()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = load(path)
    except RigFileError as exc:
        assert str(path) in str(exc), f"error does not name the file: {exc}"
        assert "\n" not in str(exc).replace(str(path), ""), f"several lines: {exc!r}"
        result = None
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    assert peak < MAX_PEAK_BYTES, f"{peak / 2**20:.0f} MB traced while loading"
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - t0
    assert cpu < MAX_CPU_SECONDS and wall < MAX_WALL_SECONDS, f"{cpu:.1f} s CPU, {wall:.1f} s"
    return result


def _mesh_ok(result):
    if result is not None:
        v, f = result
        assert len(f) and np.all(np.isfinite(v)) and f.min() >= 0 and f.max() < len(v)


def _skeleton_ok(result):
    if result is not None:
        sk, meta = result
        assert np.all(np.isfinite(sk.bind_matrices)) and meta["up"] in ("y", "z")
        assert np.all(np.isfinite(sk.inverse_bind_matrices))


def _clip_ok(result):
    if result is not None:
        assert np.isfinite(result.duration) and isinstance(result.loop, bool)
        pose = result.sample(result.duration / 2)
        assert np.all(np.isfinite(pose.translation)) and np.all(np.isfinite(pose.rotation))


MESH_FORMATS = ["obj", "ply", "ply_ascii", "stl", "vtk", "vtu", "vtp"]


@pytest.mark.parametrize("fmt", MESH_FORMATS)
def test_fuzz_mesh(base, fmt):
    ext = "ply" if fmt == "ply_ascii" else fmt
    path = base["scratch"] / f"m.{ext}"

    @FUZZ
    @given(mutated(base["files"][fmt]))
    def run(data):
        _mesh_ok(_load_checked(_put(path, data), load_mesh))
    run()


def _fuzz_json(path, data, load, check):
    """Mutations of the JSON file ``data`` written to ``path``, each through ``load``."""
    @FUZZ
    @given(mutated(data, json.loads(data)))
    def run(text):
        check(_load_checked(_put(path, text), load))
    run()


@pytest.mark.parametrize("fmt", ["skeleton", "elk_skeleton"])
def test_fuzz_skeleton(base, fmt):
    _fuzz_json(base["scratch"] / "skeleton.json", base["files"][fmt], load_skeleton,
               _skeleton_ok)


@pytest.mark.parametrize("fmt", ["clip", "elk_clip"])
def test_fuzz_clip(base, fmt):
    skeleton = base["rig" if fmt == "clip" else "elk"].skeleton
    _fuzz_json(base["scratch"] / "walk.json", base["files"][fmt],
               lambda p: load_clip(p, skeleton), _clip_ok)


def test_fuzz_weights(base):
    path = base["scratch"] / "weights.npz"
    rig = base["rig"]
    plain = corpus.npz_bytes(**corpus.good_weights(base["rig_dir"]))   # uncompressed

    @FUZZ
    @given(st.one_of(byte_mutation(base["files"]["weights"]), byte_mutation(plain),
                     npz_mutation(plain), npz_mutation(plain)))
    def run(data):
        result = _load_checked(_put(path, data),
                               lambda p: load_weights(p, rig.skeleton, len(rig.vertices)))
        if result is not None:
            idx, w = result
            assert idx.min() >= 0 and idx.max() < len(rig.skeleton)
            assert np.all(w >= 0) and np.allclose(w.sum(axis=1), 1.0)
    run()


def test_fuzz_rig_json(base):
    folder = base["scratch"] / "rig"
    if not folder.exists():
        shutil.copytree(base["rig_dir"], folder)
    data = base["files"]["rig_json"]

    @FUZZ
    @given(mutated(data, json.loads(data)))
    def run(text):
        (folder / "rig.json").write_bytes(text)
        rig = _load_checked(folder, load_rig_folder)
        if rig is not None:
            assert rig.up in ("y", "z") and isinstance(rig.name, str)
    run()


# ---------------------------------------------------------------------------- glTF, GLB, BVH
#: What the glTF and BVH readers must also survive (issue 19): counts that claim terabytes,
#: indices past every table, nesting thousands deep, numbers beyond float range.
GLTF_RAW = ["1099511627776", "4294967295", "2147483647", "-2", "1e400", "-1e400", "3e38",
            "[" * 2000 + "]" * 2000, '"/etc/passwd"', '"../../../../dev/zero"',
            '"file:///etc/passwd"', '"data:,"', '"data:application/octet-stream;base64,@@"']
BVH_TOKENS = ["inf", "-inf", "nan", "1e400", "1e30", "-1e30", "3e38", "0", "-0", "1e-320",
              "\u00b3", "\uff13", "\u0663", "x", "", "999999999999", "{", "}", "JOINT",
              "End Site", "CHANNELS", "MOTION"]


@pytest.fixture(scope="module")
def rig_files(tmp_path_factory):
    """A small rig (3 joints, a clip) written by rigedit as GLB, embedded glTF and BVH."""
    from rigedit.io.bvh_write import save_bvh
    from rigedit.io.gltf_write import save_gltf

    root = tmp_path_factory.mktemp("fuzz_rig")
    rig = corpus.small_rig()
    save_gltf(rig.data(), root / "r.glb")
    save_gltf(rig.data(), root / "r.gltf")   # a data uri: one self-contained file
    save_bvh(rig, root / "r.bvh")
    scratch = root / "scratch"
    scratch.mkdir()
    return {name: (root / name).read_bytes() for name in ("r.glb", "r.gltf", "r.bvh")} | {
        "scratch": scratch}


def _rig_ok(result):
    if result is not None:
        assert len(result.skeleton) >= 1
        assert np.all(np.isfinite(result.skin(result.rest_pose())))
        for clip in result.clips.values():
            pose = clip.sample(clip.duration / 2)
            assert np.all(np.isfinite(pose.translation)) and np.all(np.isfinite(pose.rotation))


def _load_rig(path):
    import rigedit

    return rigedit.load_rig(path, scale=0.01) if path.suffix == ".bvh" else \
        rigedit.load_rig(path)


def _glb_parts(data):
    """(JSON object, BIN chunk bytes) of a GLB rigedit wrote."""
    import struct

    size = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + size])
    rest = data[20 + size:]
    return doc, rest[8:] if len(rest) >= 8 else b""


def _glb(json_bytes, bin_chunk):
    import struct

    body = json_bytes + b" " * (-len(json_bytes) % 4)
    chunks = struct.pack("<II", len(body), 0x4E4F534A) + body
    if bin_chunk:
        chunks += struct.pack("<II", len(bin_chunk), 0x004E4942) + bin_chunk
    return b"glTF" + struct.pack("<II", 2, 12 + len(chunks)) + chunks


@st.composite
def gltf_claim(draw, doc):
    """An accessor made to claim a huge count (with or without its bufferView, or sparse),
    or a node made thousands deep, as JSON text."""
    doc = copy.deepcopy(doc)
    op = draw(st.sampled_from(["count", "unbacked", "sparse", "deep_extras", "chain"]))
    accessors = doc.get("accessors") or [{}]
    acc = accessors[draw(st.integers(0, len(accessors) - 1))]
    if op == "count":
        acc["count"] = draw(st.sampled_from([2**40, 2**31, 2**26 + 1, 10**6]))
    elif op == "unbacked":
        acc.pop("bufferView", None)
        acc["count"] = draw(st.sampled_from([2**40, 2**28, 10**7, 10**5]))
    elif op == "sparse":
        view = acc.get("bufferView", 0)
        acc["sparse"] = {"count": draw(st.sampled_from([2**31, 10**6, 2])),
                         "indices": {"bufferView": view, "componentType": 5125},
                         "values": {"bufferView": view}}
    elif op == "deep_extras":
        depth = draw(st.sampled_from([101, 900, 5000]))
        doc.setdefault("nodes", [{}])[0]["extras"] = "@@DEEP@@"
        return json.dumps(doc).replace('"@@DEEP@@"', "[" * depth + "]" * depth).encode()
    else:
        nodes = doc.setdefault("nodes", [])
        n0 = len(nodes)
        depth = draw(st.sampled_from([100, 3000]))
        nodes += [{"children": [n0 + i + 1]} for i in range(depth - 1)] + [{}]
    return json.dumps(doc).encode()


def _address_space_cap(extra=2 * 2**30):
    """Cap this process's address space at its current size plus ``extra`` for the block, so
    that an allocation from a file's claim fails (MemoryError, a failed example) instead of
    bringing the machine's OOM killer; returns a function that lifts the cap."""
    import resource

    with open("/proc/self/status") as fh:
        size = next(int(line.split()[1]) * 1024 for line in fh if line.startswith("VmSize:"))
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = size + extra
    resource.setrlimit(resource.RLIMIT_AS, (cap if hard < 0 else min(cap, hard), hard))
    return lambda: resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


def _fuzz_rig_file(path, strategy):
    @FUZZ
    @given(strategy)
    def run(data):
        _rig_ok(_load_checked(_put(path, data), _load_rig))
    lift = _address_space_cap()
    try:
        run()
    finally:
        lift()


def test_fuzz_gltf(rig_files):
    data = rig_files["r.gltf"]
    doc = json.loads(data)
    _fuzz_rig_file(rig_files["scratch"] / "f.gltf",
                   st.one_of(byte_mutation(data), json_mutation(doc), json_mutation(doc),
                             gltf_claim(doc), st.sampled_from(GLTF_RAW).map(
                                 lambda raw: data.replace(b'"count":', b'"count":' +
                                                          raw.encode() + b', "x":'))))


def test_fuzz_glb(rig_files):
    data = rig_files["r.glb"]
    doc, bin_chunk = _glb_parts(data)
    # structural edits of the JSON chunk, repacked so the container stays valid and the
    # edit reaches the readers behind it; and raw byte edits of the container itself
    repacked = st.one_of(json_mutation(doc), gltf_claim(doc)).map(
        lambda text: _glb(text, bin_chunk))
    _fuzz_rig_file(rig_files["scratch"] / "f.glb",
                   st.one_of(byte_mutation(data), byte_mutation(data), repacked, repacked))


@st.composite
def bvh_mutation(draw, text):
    """BVH text with tokens replaced (non-finite, huge, non-ASCII digits, stray braces),
    lines dropped or repeated, or the hierarchy nested thousands deep."""
    lines = text.split("\n")
    for _ in range(draw(st.integers(1, 3))):
        op = draw(st.sampled_from(["token", "token", "drop", "repeat", "deep", "frames"]))
        i = draw(st.integers(0, len(lines) - 1))
        if op == "token":
            words = lines[i].split(" ")
            k = draw(st.integers(0, max(len(words) - 1, 0)))
            words[k] = draw(st.sampled_from(BVH_TOKENS))
            lines[i] = " ".join(words)
        elif op == "drop":
            del lines[i]
        elif op == "repeat":
            lines[i:i] = lines[i:i + draw(st.integers(1, 8))]
        elif op == "deep":
            depth = draw(st.sampled_from([999, 1001, 10000]))
            at = next((n for n, line in enumerate(lines) if "End Site" in line), None)
            if at is not None:
                lines[at:at] = ["JOINT d{0}\n{{\nOFFSET 0 1 0".format(n)
                                for n in range(depth)]
                end = next(n for n in range(at + depth, len(lines)) if "}" in lines[n])
                lines[end + 1:end + 1] = ["}"] * depth
        else:
            at = next((n for n, line in enumerate(lines) if line.startswith("Frames:")), None)
            if at is not None:
                lines[at] = "Frames: " + draw(st.sampled_from(["0", "inf", "nan", "-1",
                                                               "\u00b3", "1e300", "2.5"]))
    return "\n".join(lines).encode()


def test_fuzz_bvh(rig_files):
    data = rig_files["r.bvh"]
    _fuzz_rig_file(rig_files["scratch"] / "f.bvh",
                   st.one_of(byte_mutation(data), bvh_mutation(data.decode()),
                             bvh_mutation(data.decode())))


# ---------------------------------------------------------------------------- FBX
FBX_FUZZ = settings(FUZZ, max_examples=max(FUZZ_EXAMPLES // 4, 5))


def test_fuzz_fbx(rig_files):
    """Binary FBX (the small rig as rigedit writes it) and ASCII FBX (tests/fbx_mini.py),
    truncated, flipped, cut and repeated, read as users read them (rigedit.load_rig: ufbx in
    a child process): each loads whole or is one RigFileError naming the file, never a crash
    of this process, never a hang."""
    from fbx_mini import mini_fbx
    from rigedit.io.fbx_write import write_fbx

    binary = rig_files["scratch"] / "src.fbx"
    write_fbx(corpus.small_rig().data(), binary)
    sources = [binary.read_bytes(), mini_fbx([(0.0, 0.0), (1.0, 100.0)]).encode()]

    @FBX_FUZZ
    @given(st.one_of(*[byte_mutation(data) for data in sources]))
    def run(data):
        _rig_ok(_load_checked(_put(rig_files["scratch"] / "f.fbx", data), _load_rig))
    run()
