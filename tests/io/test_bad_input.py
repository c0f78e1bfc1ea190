"""Every bad input gets one RigFileError naming the file (issue 8, section 3).

The corpus of ``bad_input_corpus.py`` (one malformed rig folder per class of failure) is
loaded in-process through ``rigedit.load_rig``; the same corpus is run through the real
command line by that module's ``__main__`` (see its docstring).
"""
import errno
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

import bad_input_corpus as corpus
import rigedit
from builders import cylinder_rig
from rigedit.errors import RigFileError
from rigedit.io import load_clip, load_mesh, load_skeleton, load_weights, save_rig_folder
from rigedit.io.jsonfile import read_json


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    return {c.name: (c, f) for c, f in corpus.build_corpus(tmp_path_factory.mktemp("corpus"))}


@pytest.mark.parametrize("name", [c.name for c in corpus.CASES])
def test_corpus_case_loads_or_names_the_file(built, name):
    case, folder = built[name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if not case.expect_error:
            rig = rigedit.load_rig(folder)
            assert np.all(np.isfinite(rig.vertices))
            return
        with pytest.raises(RigFileError) as err:
            rigedit.load_rig(folder)
    message = str(err.value)
    assert str(folder / case.culprit) in message, message
    assert "\n" not in message and len(message) < 800 + len(str(folder)) * 2


def test_corpus_has_a_hundred_cases():
    assert len(corpus.CASES) >= 100
    assert len({c.name for c in corpus.CASES}) == len(corpus.CASES)


# ---------------------------------------------------------------------------- specifics
def test_obj_tabs_leading_spaces_and_bom_load_like_the_plain_file(tmp_path):
    plain = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n"
    ref = load_mesh(_write(tmp_path / "a.obj", plain))
    for i, text in enumerate(["\ufeff" + plain, plain.replace(" ", "\t"),
                              "".join("  \t" + ln + "\n" for ln in plain.splitlines())]):
        v, f = load_mesh(_write(tmp_path / f"b{i}.obj", text))
        assert np.array_equal(v, ref[0]) and np.array_equal(f, ref[1])


def _write(path, text, binary=False):
    path.write_bytes(text) if binary else path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("text,msg", [
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "line 4: face index 0"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 " + "9" * 40 + "\n", "line 4: expected face indices up to"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -7\n", "face index out of range"),
    ("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "none among 1"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 1 2\nf 2 3 3\n", "none among 2"),
    ("v 0 0 0\nv 1e12 0 0\nv 0 1 0\nf 1 2 3\n", "within"),
    ("", "no faces"),
])
def test_bad_obj(tmp_path, text, msg):
    p = _write(tmp_path / "m.obj", text)
    with pytest.raises(RigFileError, match=msg) as err:
        load_mesh(p)
    assert str(p) in str(err.value)


def test_binary_obj_is_named_as_binary(tmp_path):
    p = _write(tmp_path / "m.obj", b"v 0 0 0\n\x00\x01\x02" * 10, binary=True)
    with pytest.raises(RigFileError, match="binary data"):
        load_mesh(p)


@pytest.mark.parametrize("ext", ["ply", "stl", "vtk", "vtu", "vtp"])
def test_third_party_readers_stay_quiet_and_raise_rigfileerror(tmp_path, ext, capfd):
    for i, data in enumerate([b"", corpus.GARBAGE, corpus.mesh_bytes(ext)[:200]]):
        p = _write(tmp_path / f"m{i}.{ext}", data, binary=True)
        with pytest.raises(RigFileError) as err:
            load_mesh(p)
        assert str(p) in str(err.value)
    out, errs = capfd.readouterr()   # file descriptors: VTK writes from C++
    assert out == "" and errs == ""


@pytest.mark.parametrize("ext", ["ply", "stl", "vtk", "vtu", "vtp"])
def test_third_party_formats_still_load(tmp_path, ext):
    v, f = load_mesh(_write(tmp_path / f"m.{ext}", corpus.mesh_bytes(ext), binary=True))
    assert len(f) == 2 * 6 * 8 + 2 * 8 and np.all(np.isfinite(v))


@pytest.mark.parametrize("text,msg", [
    ('{"up": NaN}', "expected finite numbers, got NaN"),
    ('{"up": -Infinity}', "got -Infinity"),
    ('{"up": 1e400}', "within float range"),
    ('{"up": ' + "9" * 400 + "}", "integer of 400 digits"),
    ('{"up": ' + "9" * 5000 + "}", "integer of 5000 digits"),
    ("[" * 100000 + "]" * 100000, "nested"),
    ('{"a": 1, "a": 2}', "key 'a' appears twice"),
    ("", "empty file"),
])
def test_json_reader_refuses(tmp_path, text, msg):
    p = _write(tmp_path / "x.json", text)
    with pytest.raises(RigFileError, match=msg) as err:
        read_json(p)
    assert str(p) in str(err.value)


def test_json_reader_accepts_a_bom_and_bad_utf8_is_named(tmp_path):
    assert read_json(_write(tmp_path / "a.json", '\ufeff{"a": [1, 2.5]}')) == {"a": [1, 2.5]}
    with pytest.raises(RigFileError, match="expected UTF-8 text"):
        read_json(_write(tmp_path / "b.json", b'{"a": "\xff"}', binary=True))


SKELETON = '{"joints": [{"name": "a", "translation": [0, 0, 0]}, {"name": "b", "parent": "a", %s}]}'


@pytest.mark.parametrize("field,msg", [
    ('"translation": ["0", "1", "0"]', "joint 'b': expected 'translation' to be a list of 3 numbers"),
    ('"translation": [true, 1, 0]', "got \\[True, 1, 0\\]"),
    ('"translation": [0, 1e200, 0]', "within \\+-1e\\+09, got 1e\\+200"),
    ('"rotation": [0, 0, 0, 0]', "unit quaternion"),
    ('"scale": [1, 0, 1]', "without a zero component"),
    ('"deform": "no"', "joint 'b': expected 'deform' to be true or false, got 'no'"),
    ('"deform": 0', "true or false, got 0"),
    ('"tail": "up"', "expected 'tail' to be a list of 3 numbers"),
])
def test_skeleton_wrong_types_are_errors(tmp_path, field, msg):
    p = _write(tmp_path / "s.json", SKELETON % field)
    with pytest.raises(RigFileError, match=msg):
        load_skeleton(p)


def test_parent_must_be_a_name(tmp_path):
    p = _write(tmp_path / "s.json", '{"joints": [{"name": "a"}, {"name": "b", "parent": ["a"]}]}')
    with pytest.raises(RigFileError, match="joint 'b': expected 'parent' to be a non-empty name"):
        load_skeleton(p)


@pytest.mark.parametrize("bad", ["a\u0000b", "a\nb", "", "x" * 300])
def test_joint_names_with_control_characters_are_errors(tmp_path, bad):
    p = tmp_path / "s.json"
    p.write_text('{"joints": [{"name": %s}]}' % __import__("json").dumps(bad))
    with pytest.raises(RigFileError, match="'name'"):
        load_skeleton(p)


def test_skeleton_up_must_be_y_or_z(tmp_path):
    p = _write(tmp_path / "s.json", '{"up": "x", "joints": [{"name": "a"}]}')
    with pytest.raises(RigFileError, match="expected 'up' to be one of 'y', 'z', got 'x'"):
        load_skeleton(p)


@pytest.mark.parametrize("top,msg", [
    ('"loop": "false"', "expected 'loop' to be true or false, got 'false'"),
    ('"loop": 0', "true or false"),
    ('"duration": "1.0"', "expected 'duration' to be a number, got '1.0'"),
    ('"duration": true', "to be a number, got true"),
    ('"duration": 1e300', "between 0 and 1e\\+06"),
    ('"name": ["bend"]', "expected 'name' to be a non-empty name"),
])
def test_clip_wrong_types_are_errors(tmp_path, top, msg):
    rig = cylinder_rig(with_clip=False)
    p = _write(tmp_path / "c.json", '{%s, "tracks": [{"joint": "j1", "channel": "rotation", '
                                   '"times": [0], "values": [[0, 0, 0, 1]]}]}' % top)
    with pytest.raises(RigFileError, match=msg):
        load_clip(p, rig.skeleton)


def test_clip_values_of_wrong_type_or_size(tmp_path):
    rig = cylinder_rig(with_clip=False)
    for times, values, msg in [('["0"]', "[[0, 0, 0, 1]]", "'times' to be a list of numbers"),
                               ("[0]", '[["0", 0, 0, 1]]', "'values' to be a list of 1 rows"),
                               ("[0, 1e300]", "[[0, 0, 0, 1], [0, 0, 0, 1]]", "within"),
                               ("[0]", "[[1e200, 0, 0, 1]]", "within")]:
        p = _write(tmp_path / "c.json", '{"tracks": [{"joint": "j1", "channel": "rotation", '
                                        f'"times": {times}, "values": {values}}}]}}')
        with pytest.raises(RigFileError, match=msg):
            load_clip(p, rig.skeleton)


def test_elk_key_time_must_be_a_number_not_a_boolean(tmp_path):
    rig = cylinder_rig(with_clip=False)
    p = _write(tmp_path / "c.json", '{"keyframes": {"j1": [{"time": true}]}}')
    with pytest.raises(RigFileError, match="expected 'time' in joint 'j1' key 0 to be"):
        load_clip(p, rig.skeleton)


# ---------------------------------------------------------------------------- weights
@pytest.fixture
def weights_case(tmp_path):
    rig = cylinder_rig(with_clip=False)
    arrays = {"indices": rig.binding.indices.astype(np.int32),
              "weights": rig.binding.weights.astype(np.float32),
              "joints": np.array(rig.skeleton.names)}

    def write(**change):
        p = tmp_path / "w.npz"
        p.write_bytes(corpus.npz_bytes(**{**arrays, **change}))
        return p
    return rig, arrays, write


def test_weights_wrong_content(weights_case):
    rig, a, write = weights_case
    n = len(rig.vertices)
    neg = a["weights"].copy()
    neg[5, 1] = -0.25
    nan = a["weights"].copy()
    nan[7, 0] = np.nan
    cases = [({"indices": a["indices"].astype(float)}, "expected integer joint indices"),
             ({"weights": neg}, "expected weights >= 0, got -0.25 at vertex 5"),
             ({"weights": nan}, "NaN or inf at vertex 7"),
             ({"weights": np.zeros_like(a["weights"])}, "vertex 0 has none"),
             ({"joints": np.array(["j0", "j0", "j2"])}, "'j0' twice"),
             ({"indices": a["indices"][:, :, None], "weights": a["weights"][:, :, None]},
              "one shape \\(V, K\\)")]
    for change, msg in cases:
        p = write(**change)
        with pytest.raises(RigFileError, match=msg) as err:
            load_weights(p, rig.skeleton, n)
        assert str(p) in str(err.value)


def test_weights_header_claiming_a_huge_shape_is_refused_before_allocating(tmp_path):
    import tracemalloc

    rig = cylinder_rig(with_clip=False)
    folder = tmp_path / "r"
    save_rig_folder(folder, rig)
    corpus.huge_header_npz(folder)
    tracemalloc.start()
    with pytest.raises(RigFileError, match="expected weights for"):
        load_weights(folder / "weights.npz", rig.skeleton, len(rig.vertices))
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 20 * 2**20


@pytest.mark.parametrize("data,msg", [(b"", "zip archive"), (b"PK\x03\x04junk", "zip archive"),
                                      (corpus.npz_bytes(x=np.zeros(2)), "missing 'indices'")])
def test_weights_not_an_npz(tmp_path, data, msg):
    p = _write(tmp_path / "w.npz", data, binary=True)
    with pytest.raises(RigFileError, match=msg):
        load_weights(p, cylinder_rig(with_clip=False).skeleton, 10)


# ---------------------------------------------------------------------------- paths
@pytest.mark.parametrize("kind,msg", [("fifo", "FIFO"), ("dir", "folder"),
                                      ("zero", "character device")])
@pytest.mark.parametrize("reader", ["json", "mesh", "weights"])
def test_not_a_regular_file_is_an_error_at_once(tmp_path, kind, msg, reader):
    p = tmp_path / {"json": "s.json", "mesh": "m.obj", "weights": "w.npz"}[reader]
    corpus.replace_path(p, kind)
    load = {"json": read_json, "mesh": load_mesh,
            "weights": lambda q: load_weights(q, cylinder_rig(False).skeleton, 10)}[reader]
    with pytest.raises(RigFileError, match=f"expected a regular file, got .*{msg}") as err:
        load(p)   # a FIFO opened for reading would wait here for ever
    assert str(p) in str(err.value)


def test_unreadable_file_and_folder(tmp_path, monkeypatch):
    rig_dir = tmp_path / "r"
    save_rig_folder(rig_dir, cylinder_rig())
    real_open = os.open

    def deny(path, *a, **k):
        if str(path).endswith("skeleton.json"):
            raise PermissionError(errno.EACCES, "Permission denied", str(path))
        return real_open(path, *a, **k)
    monkeypatch.setattr(os, "open", deny)
    with pytest.raises(RigFileError, match="skeleton.json: permission denied"):
        rigedit.load_rig(rig_dir)
    monkeypatch.undo()

    from pathlib import Path
    real_iterdir = Path.iterdir

    def deny_dir(self):
        if self.name == "animations":
            raise PermissionError(errno.EACCES, "Permission denied", str(self))
        return real_iterdir(self)
    monkeypatch.setattr(Path, "iterdir", deny_dir)
    with pytest.raises(RigFileError, match="animations: permission denied"):
        rigedit.load_rig(rig_dir)


def test_names_too_long(tmp_path):
    with pytest.raises(RigFileError, match="file name too long"):
        rigedit.load_rig(tmp_path / ("x" * 300))
    with pytest.raises(RigFileError, match="file name too long"):
        load_mesh(tmp_path / ("m" * 300 + ".obj"))


def test_two_meshes_without_manifest_name_both(tmp_path):
    rig_dir = tmp_path / "r"
    save_rig_folder(rig_dir, cylinder_rig())
    (rig_dir / "rig.json").unlink()
    (rig_dir / "extra.ply").write_bytes(corpus.mesh_bytes("ply"))
    with pytest.raises(RigFileError, match="got 2: extra.ply, mesh.obj") as err:
        rigedit.load_rig(rig_dir)
    assert str(rig_dir) in str(err.value)


def test_elk_models_parts_are_still_merged(built):
    case, folder = built["elk_two_parts_merge"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig = rigedit.load_rig(folder)
    assert rig.bounds()[1][0] == pytest.approx(2.0)   # the box part reaches x = 2


# ---------------------------------------------------------------------------- CLI
def _cli(*argv, timeout=120):
    return subprocess.run([sys.executable, "-m", "rigedit", *map(str, argv)],
                          capture_output=True, text=True, timeout=timeout)


@pytest.mark.parametrize("option,value,msg", [
    ("--fps", "nan", "--fps"), ("--fps", "inf", "--fps"), ("--fps", "0", "--fps"),
    ("--fps", "1000", "--fps"), ("--duration", "nan", "--duration"),
    ("--duration", "1e12", "--duration"), ("--duration", "-1", "--duration"),
    ("--angle", "inf", "--angle"), ("--angle", "nan", "--angle"),
    ("--size", "0x0", "--size"), ("--size", "100000x720", "--size"),
    ("--size=-5x10", None, "--size"),
])
def test_render_options_are_checked(tmp_path, option, value, msg):
    from rigedit.cli.main import main

    rig_dir = tmp_path / "r"
    save_rig_folder(rig_dir, cylinder_rig())
    argv = ["render", "bend", "--rig", str(rig_dir), "-o", str(tmp_path / "x.gif"), option]
    argv += [value] if value is not None else []
    import io
    from contextlib import redirect_stderr

    err = io.StringIO()
    with redirect_stderr(err):
        assert main(argv) == 2
    lines = err.getvalue().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"rigedit: error: {msg}")
    assert not (tmp_path / "x.gif").exists()


@pytest.mark.parametrize("k", ["0", "9", "-1", "1000000"])
def test_max_influences_is_checked(tmp_path, k, capsys):
    from rigedit.cli.main import main

    rig_dir = tmp_path / "r"
    save_rig_folder(rig_dir, cylinder_rig())
    assert main(["weights", str(rig_dir), "--max-influences", k, "-o",
                 str(tmp_path / "w.npz")]) == 2
    assert capsys.readouterr().err.startswith("rigedit: error: --max-influences")


def test_cli_fifo_skeleton_is_one_line_and_no_wait(tmp_path):
    rig_dir = tmp_path / "r"
    save_rig_folder(rig_dir, cylinder_rig())
    corpus.replace_path(rig_dir / "skeleton.json", "fifo")
    proc = _cli("info", rig_dir, timeout=60)
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [
        f"rigedit: error: {rig_dir / 'skeleton.json'}: expected a regular file, got a FIFO "
        "(named pipe)"]


def test_many_joints_load_without_a_joints_squared_table(tmp_path):
    """30,000 joints (the corpus had 100,000, which loads in about 5 s): no (J, J) table is
    made on load or an LBS frame (the DQS hemisphere table waits for the first DQS frame);
    the peak stays far below the 3.6 GB of a float32 one."""
    import json
    import tracemalloc

    rig_dir = tmp_path / "r"
    save_rig_folder(rig_dir, cylinder_rig())
    data = json.loads((rig_dir / "skeleton.json").read_text())
    root = data["joints"][0]["name"]
    data["joints"] += [{"name": f"x{i}", "parent": root, "translation": [0, 1e-3 * i, 0]}
                       for i in range(30_000)]
    (rig_dir / "skeleton.json").write_text(json.dumps(data))
    tracemalloc.start()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rig = rigedit.load_rig(rig_dir)
        rig.skin(rig.rest_pose())
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert len(rig.skeleton.names) == 30_003
    assert peak < 1 * 2**30, peak
