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
