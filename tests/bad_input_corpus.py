"""A corpus of malformed rig folders, one per class of bad input (issue 8, section 3).

Each case is a copy of a small valid rig folder (rigedit or elk layout) with one thing broken.
``tests/test_bad_input.py`` loads every case in-process; run this module to write the corpus
to a folder and push every case through the real command line (``info``, ``list``,
``weights``, ``render``) and ``rigedit.load_rig`` in subprocesses with a time and memory
limit, counting the outcomes::

    .venv/bin/python tests/bad_input_corpus.py /tmp/corpus [--jobs 2] [--no-render]

A good outcome for a broken folder is exit status 2 with exactly one ``rigedit: error:``
line naming the broken file, nothing else on stderr but warnings, and no traceback; for a
folder that is valid although unusual (tabs in an OBJ, a BOM, the elk layout's several
parts) it is exit status 0.
"""
from __future__ import annotations

import json
import os
import shutil
import struct
import sys
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))


@dataclass
class Case:
    """One corpus folder: ``culprit`` is the file (relative to the folder) a good error names,
    or None when the folder is valid and must load."""

    name: str
    layout: str
    culprit: str | None
    mutate: object

    @property
    def expect_error(self):
        return self.culprit is not None


CASES = []


def case(name, culprit, layout="rigedit"):
    def deco(fn):
        CASES.append(Case(name, layout, culprit, fn))
        return fn
    return deco


# ---------------------------------------------------------------------------- base folders
def small_rig():
    """A 3-joint cylinder rig with a clip named ``walk`` (so ``render walk`` works)."""
    from builders import chain_skeleton, cylinder
    from rigedit.animation import Clip, Track
    from rigedit.model.transforms import euler_to_quat
    from rigedit.rig import Rig

    sk = chain_skeleton(3)
    v, f = cylinder(rings=7, segments=8)
    q = euler_to_quat([[0, 0, 0], [0, 0, 60], [0, 0, 0]], degrees=True)
    clip = Clip("walk", sk, {("j1", "rotation"): Track("rotation", [0, .5, 1], q),
                             ("j0", "translation"): Track("translation", [0, 1],
                                                          [[0, 0, 0], [0, 0, 1]])})
    return Rig(sk, v, f, clips={"walk": clip}, name="small")


def write_base(folder, layout):
    from builders import write_elk_folder
    from rigedit.io import save_rig_folder

    if layout == "rigedit":
        save_rig_folder(folder, small_rig())
    else:
        write_elk_folder(folder)
        bow = json.loads((folder / "animations" / "bow.json").read_text())
        bow["name"] = "walk"
        (folder / "animations" / "bow.json").unlink()
        (folder / "animations" / "walk.json").write_text(json.dumps(bow))
    return folder


def build_corpus(root):
    """Write every case under ``root`` (emptied first); returns ``[(Case, folder)]``."""
    root = Path(root)
    if root.exists():
        shutil.rmtree(root)
    root.mkdir(parents=True)
    bases = {lay: write_base(root / f"_base_{lay}", lay) for lay in ("rigedit", "elk")}
    out = []
    for c in CASES:
        folder = root / c.name
        shutil.copytree(bases[c.layout], folder, symlinks=True)
        c.mutate(folder)
        out.append((c, folder))
    for base in bases.values():
        shutil.rmtree(base)
    return out


# ---------------------------------------------------------------------------- helpers
def edit_json(path, fn):
    data = json.loads(path.read_text())
    fn(data)
    path.write_text(json.dumps(data))


def set_text(path, text, mode="w"):
    path.parent.mkdir(parents=True, exist_ok=True)
    if mode == "wb":
        path.write_bytes(text)
    else:
        path.write_text(text)


def replace_path(path, kind):
    """Make ``path`` a FIFO, a folder, or a link to a device instead of a regular file."""
    if path.exists() or path.is_symlink():
        if path.is_dir():
            shutil.rmtree(path)
        else:
            path.unlink()
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "dir":
        path.mkdir()
    elif kind == "zero":
        path.symlink_to("/dev/zero")
    elif kind == "null":
        path.symlink_to("/dev/null")


def sk(folder):
    return folder / "skeleton.json"


def clip(folder):
    return folder / "animations" / "walk.json"


def elk_sk(folder):
    return folder / "skeleton" / "skeleton.json"


def elk_clip(folder):
    return folder / "animations" / "walk.json"


def joint_edit(key, value, index=1):
    def fn(folder):
        def change(d):
            d["joints"][index][key] = value
        edit_json(sk(folder), change)
    return fn


def raw_joint_edit(path_fn, key, raw, index=1):
    """Put ``raw`` JSON text (NaN, huge integers, ...) as a joint's field."""
    def fn(folder):
        p = path_fn(folder)
        d = json.loads(p.read_text())
        d["joints"][index][key] = "@@RAW@@"
        p.write_text(json.dumps(d).replace('"@@RAW@@"', raw))
    return fn


def top_edit(path_fn, key, value=None, raw=None):
    def fn(folder):
        p = path_fn(folder)
        d = json.loads(p.read_text())
        d[key] = "@@RAW@@" if raw is not None else value
        p.write_text(json.dumps(d).replace('"@@RAW@@"', raw) if raw is not None else json.dumps(d))
    return fn


def track_edit(key, value=None, raw=None, index=0):
    def fn(folder):
        d = json.loads(clip(folder).read_text())
        d["tracks"][index][key] = "@@RAW@@" if raw is not None else value
        text = json.dumps(d)
        clip(folder).write_text(text.replace('"@@RAW@@"', raw) if raw is not None else text)
    return fn


def elk_key_edit(key, value=None, raw=None):
    def fn(folder):
        d = json.loads(elk_clip(folder).read_text())
        d["keyframes"]["spine"][1][key] = "@@RAW@@" if raw is not None else value
        text = json.dumps(d)
        elk_clip(folder).write_text(text.replace('"@@RAW@@"', raw) if raw is not None else text)
    return fn


def rig_json_edit(key, value=None, raw=None):
    return top_edit(lambda f: f / "rig.json", key, value, raw)


def obj_lines(folder):
    return (folder / "mesh.obj").read_text().splitlines()


def write_obj(folder, lines):
    (folder / "mesh.obj").write_text("\n".join(lines) + "\n")


def replace_mesh(folder, name, data):
    """Replace mesh.obj with ``name`` holding ``data`` (bytes) and point rig.json at it."""
    (folder / "mesh.obj").unlink()
    (folder / name).write_bytes(data)
    edit_json(folder / "rig.json", lambda d: d.__setitem__("mesh", name))


def mesh_bytes(ext, binary=True, **kw):
    import meshio

    from builders import cylinder

    v, f = cylinder(rings=7, segments=8)
    f = f.astype(np.int32)   # PLY has no 64-bit integers (meshio would say so)
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / f"m.{ext}"
        if ext == "vtp":
            import pyvista as pv

            pv.PolyData.from_regular_faces(v, f).save(p)
        else:
            meshio.write_points_cells(p, v, [("triangle", f)], binary=binary, **kw)
        return p.read_bytes()


def npz_bytes(**arrays):
    import io

    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def good_weights(folder):
    with np.load(folder / "weights.npz") as d:
        return {k: d[k] for k in d.files}


def weights_edit(fn):
    def mutate(folder):
        arrays = good_weights(folder)
        fn(arrays)
        (folder / "weights.npz").write_bytes(npz_bytes(**arrays))
    return mutate


HUGE_INT = "1" + "0" * 400          # too large for a float
LONG_INT = "7" * 5000               # beyond Python's int-string conversion limit
DEEP = "[" * 100000 + "]" * 100000  # RecursionError in json
GARBAGE = bytes(np.random.default_rng(8).integers(0, 256, 4000, dtype=np.uint8))

# ---------------------------------------------------------------------------- rig.json
case("rigjson_mesh_list", "rig.json")(rig_json_edit("mesh", ["mesh.obj"]))
case("rigjson_mesh_number", "rig.json")(rig_json_edit("mesh", 3))
# null is a rig without a mesh: refused where the folder has weights for one (issue 19)
case("rigjson_mesh_null", "rig.json")(rig_json_edit("mesh", None))
case("rigjson_mesh_empty", "rig.json")(rig_json_edit("mesh", ""))
case("rigjson_skeleton_bool", "rig.json")(rig_json_edit("skeleton", True))
case("rigjson_weights_object", "rig.json")(rig_json_edit("weights", {}))
case("rigjson_up_x", "rig.json")(rig_json_edit("up", "x"))
case("rigjson_up_number", "rig.json")(rig_json_edit("up", 1))
case("rigjson_name_list", "rig.json")(rig_json_edit("name", ["a"]))
case("rigjson_name_nul", "rig.json")(rig_json_edit("name", "a\u0000b"))
case("rigjson_name_newline", "rig.json")(rig_json_edit("name", "a\nb"))
case("rigjson_name_nan", "rig.json")(rig_json_edit("name", raw="NaN"))
case("rigjson_mesh_too_long", "rig.json")(rig_json_edit("mesh", "m" * 5000 + ".obj"))
case("rigjson_mesh_missing", "nothere.obj")(rig_json_edit("mesh", "nothere.obj"))
case("rigjson_list", "rig.json")(lambda f: set_text(f / "rig.json", "[1, 2]"))
case("rigjson_malformed", "rig.json")(lambda f: set_text(f / "rig.json", '{"mesh": '))
case("rigjson_empty", "rig.json")(lambda f: set_text(f / "rig.json", ""))
case("rigjson_deep", "rig.json")(lambda f: set_text(f / "rig.json", DEEP))
case("rigjson_long_int", "rig.json")(rig_json_edit("up", raw=LONG_INT))
case("rigjson_fifo", "rig.json")(lambda f: replace_path(f / "rig.json", "fifo"))
case("rigjson_dir", "rig.json")(lambda f: replace_path(f / "rig.json", "dir"))
case("rigjson_dev_zero", "rig.json")(lambda f: replace_path(f / "rig.json", "zero"))
case("rigjson_binary", "rig.json")(lambda f: set_text(f / "rig.json", GARBAGE, "wb"))

# ---------------------------------------------------------------------------- skeleton (rigedit)
case("sk_translation_strings", "skeleton.json")(joint_edit("translation", ["0", "1", "0"]))
case("sk_translation_bools", "skeleton.json")(joint_edit("translation", [True, False, 0]))
case("sk_translation_object", "skeleton.json")(joint_edit("translation", {"x": 1}))
case("sk_translation_string", "skeleton.json")(joint_edit("translation", "0 1 0"))
case("sk_translation_nested", "skeleton.json")(joint_edit("translation", [[0], [1], [0]]))
case("sk_translation_huge_int", "skeleton.json")(
    raw_joint_edit(sk, "translation", f"[0, {HUGE_INT}, 0]"))
case("sk_translation_long_int", "skeleton.json")(
    raw_joint_edit(sk, "translation", f"[0, {LONG_INT}, 0]"))
case("sk_translation_nan", "skeleton.json")(raw_joint_edit(sk, "translation", "[0, NaN, 0]"))
case("sk_translation_inf", "skeleton.json")(
    raw_joint_edit(sk, "translation", "[0, Infinity, 0]"))
case("sk_translation_1e200", "skeleton.json")(joint_edit("translation", [0, 1e200, 0]))
case("sk_translation_1e300", "skeleton.json")(joint_edit("translation", [1e300, 1e300, 0]))
case("sk_rotation_zero", "skeleton.json")(joint_edit("rotation", [0, 0, 0, 0]))
case("sk_rotation_1e200", "skeleton.json")(joint_edit("rotation", [1e200, 0, 0, 1e200]))
case("sk_scale_zero", "skeleton.json")(joint_edit("scale", [0, 0, 0]))
case("sk_scale_strings", "skeleton.json")(joint_edit("scale", ["1", "1", "1"]))
case("sk_tail_string", "skeleton.json")(joint_edit("tail", "up", index=2))
case("sk_deform_no", "skeleton.json")(joint_edit("deform", "no"))
case("sk_deform_zero", "skeleton.json")(joint_edit("deform", 0))
case("sk_name_list", "skeleton.json")(joint_edit("name", ["j1"]))
case("sk_name_nul", "skeleton.json")(joint_edit("name", "j\u00001"))
case("sk_name_newline", "skeleton.json")(joint_edit("name", "j\n1"))
# issue 19: the rig-folder fuzz corpus's leftovers
case("sk_translation_null", "skeleton.json")(joint_edit("translation", None))
case("sk_rotation_null", "skeleton.json")(joint_edit("rotation", None))
case("sk_scale_null", "skeleton.json")(joint_edit("scale", None))
case("sk_none_deforms", "skeleton.json")(lambda f: edit_json(sk(f), lambda d: [
    j.update(deform=False) for j in d["joints"]]))


@case("sk_name_tab", None)
def _tab_name(folder):
    """A joint name with a tab: the format allows it (the weights are computed again, the
    weights file naming the old name being removed)."""
    edit_json(sk(folder), lambda d: d["joints"][2].update(name="j\t2"))
    (folder / "weights.npz").unlink()
case("sk_parent_list", "skeleton.json")(joint_edit("parent", ["j0"]))
case("sk_parent_number", "skeleton.json")(joint_edit("parent", 0))
case("sk_parent_object", "skeleton.json")(joint_edit("parent", {"name": "j0"}))
case("sk_parent_self", "skeleton.json")(joint_edit("parent", "j1"))
case("sk_cycle", "skeleton.json")(joint_edit("parent", "j2", index=0))
case("sk_duplicate_name", "skeleton.json")(joint_edit("name", "j0"))
case("sk_up_x", "skeleton.json")(top_edit(sk, "up", "x"))
case("sk_joints_object", "skeleton.json")(top_edit(sk, "joints", {"j0": {}}))
case("sk_joints_empty", "skeleton.json")(top_edit(sk, "joints", []))
case("sk_joints_numbers", "skeleton.json")(top_edit(sk, "joints", [1, 2]))
case("sk_empty", "skeleton.json")(lambda f: set_text(sk(f), ""))
case("sk_binary", "skeleton.json")(lambda f: set_text(sk(f), GARBAGE, "wb"))
case("sk_utf16", "skeleton.json")(
    lambda f: set_text(sk(f), sk(f).read_text().encode("utf-16"), "wb"))
case("sk_deep", "skeleton.json")(lambda f: set_text(sk(f), DEEP))
case("sk_truncated", "skeleton.json")(
    lambda f: set_text(sk(f), sk(f).read_text()[: len(sk(f).read_text()) // 2]))
case("sk_fifo", "skeleton.json")(lambda f: replace_path(sk(f), "fifo"))
case("sk_dir", "skeleton.json")(lambda f: replace_path(sk(f), "dir"))
case("sk_dev_zero", "skeleton.json")(lambda f: replace_path(sk(f), "zero"))
case("sk_dev_null", "skeleton.json")(lambda f: replace_path(sk(f), "null"))

# ---------------------------------------------------------------------------- skeleton (elk)
for _name, _raw in [("head_strings", '["0", "0", "1"]'), ("head_bools", "[true, false, 1]"),
                    ("head_nan", "[0, 0, NaN]"), ("head_1e200", "[0, 0, 1e200]"),
                    ("head_huge_int", f"[0, 0, {HUGE_INT}]"), ("tail_object", '{"z": 1}'),
                    ("parent_list", '["hip"]'), ("name_number", "7")]:
    _key = _name.split("_")[0]
    case(f"elk_sk_{_name}", "skeleton/skeleton.json", "elk")(
        raw_joint_edit(elk_sk, _key, _raw, index=2))
case("elk_sk_hierarchy_number", "skeleton/skeleton.json", "elk")(
    lambda f: edit_json(elk_sk(f), lambda d: ([j.pop("parent") for j in d["joints"]],
                                              d.__setitem__("hierarchy", {"hip": 0}))))
case("elk_sk_hierarchy_list", "skeleton/skeleton.json", "elk")(
    lambda f: edit_json(elk_sk(f), lambda d: ([j.pop("parent") for j in d["joints"]],
                                              d.__setitem__("hierarchy", [["hip", None]]))))

# ---------------------------------------------------------------------------- clips (rigedit)
A = "animations/walk.json"
case("clip_loop_string", A)(top_edit(clip, "loop", "false"))
case("clip_loop_number", A)(top_edit(clip, "loop", 0))
case("clip_duration_string", A)(top_edit(clip, "duration", "1.0"))
case("clip_duration_bool", A)(top_edit(clip, "duration", True))
case("clip_duration_negative", A)(top_edit(clip, "duration", -1))
case("clip_duration_nan", A)(top_edit(clip, "duration", raw="NaN"))
case("clip_duration_inf", A)(top_edit(clip, "duration", raw="Infinity"))
case("clip_duration_huge_int", A)(top_edit(clip, "duration", raw=HUGE_INT))
case("clip_duration_1e300", A)(top_edit(clip, "duration", 1e300))
case("clip_name_list", A)(top_edit(clip, "name", ["walk"]))
case("clip_name_nul", A)(top_edit(clip, "name", "wa\u0000lk"))
case("clip_name_newline", A)(top_edit(clip, "name", "wa\nlk"))
case("clip_tracks_object", A)(top_edit(clip, "tracks", {}))
case("clip_times_strings", A)(track_edit("times", ["0", "0.5", "1"]))
case("clip_times_bools", A)(track_edit("times", [False, True, 2]))
case("clip_times_huge_int", A)(track_edit("times", raw=f"[0, 0.5, {HUGE_INT}]"))
case("clip_times_long_int", A)(track_edit("times", raw=f"[0, 0.5, {LONG_INT}]"))
case("clip_times_1e300", A)(track_edit("times", [0, 0.5, 1e300]))
case("clip_times_negative", A)(track_edit("times", [-0.5, 0.5, 1]))
case("clip_values_width", A)(track_edit("values", [[0, 0, 0], [0, 0, 0], [0, 0, 0]]))
case("clip_values_nan", A)(
    track_edit("values", raw="[[0, 0, 0, 1], [0, 0, NaN, 1], [0, 0, 0, 1]]"))
case("clip_values_1e200", A)(
    track_edit("values", [[0, 0, 0, 1], [1e200, 0, 0, 1e200], [0, 0, 0, 1]]))
case("clip_translation_1e200", A)(
    track_edit("values", [[0, 0, 0], [0, 0, 1e200]], index=1))
case("clip_values_strings", A)(
    track_edit("values", [["0", "0", "0", "1"]] * 3))
case("clip_interp_number", A)(track_edit("interpolation", 3))
case("clip_interp_unknown", A)(track_edit("interpolation", "cubic"))
case("clip_channel_list", A)(track_edit("channel", ["rotation"]))
case("clip_joint_null", A)(track_edit("joint", None))
case("clip_empty", A)(lambda f: set_text(clip(f), ""))
case("clip_binary", A)(lambda f: set_text(clip(f), GARBAGE, "wb"))
case("clip_deep", A)(lambda f: set_text(clip(f), DEEP))
case("clip_list", A)(lambda f: set_text(clip(f), "[]"))
case("clip_fifo", A)(lambda f: replace_path(clip(f), "fifo"))
case("clip_dir", A)(lambda f: replace_path(clip(f), "dir"))
case("clip_dev_zero", A)(lambda f: replace_path(clip(f), "zero"))

# ---------------------------------------------------------------------------- clips (elk)
case("elk_clip_time_bool", A, "elk")(elk_key_edit("time", True))
case("elk_clip_time_string", A, "elk")(elk_key_edit("time", "1.0"))
case("elk_clip_rotation_strings", A, "elk")(elk_key_edit("rotation", ["0.5", "0", "0"]))
case("elk_clip_rotation_1e200", A, "elk")(elk_key_edit("rotation", [1e200, 0, 0]))
case("elk_clip_translation_huge_int", A, "elk")(
    elk_key_edit("translation", raw=f"[0, 0, {HUGE_INT}]"))
case("elk_clip_scale_nan", A, "elk")(elk_key_edit("scale", raw="[1, NaN, 1]"))
case("elk_clip_duration_bool", A, "elk")(top_edit(elk_clip, "duration", True))
case("elk_clip_loop_string", A, "elk")(top_edit(elk_clip, "loop", "no"))
case("elk_clip_keyframes_list", A, "elk")(top_edit(elk_clip, "keyframes", []))
case("elk_clip_keys_object", A, "elk")(
    lambda f: edit_json(elk_clip(f), lambda d: d["keyframes"].__setitem__("spine", {"time": 0})))

# ---------------------------------------------------------------------------- meshes
M = "mesh.obj"
case("obj_empty", M)(lambda f: set_text(f / M, ""))
case("obj_binary", M)(lambda f: set_text(f / M, GARBAGE, "wb"))
case("obj_truncated", M)(lambda f: set_text(f / M, (f / M).read_text()[:2000]))
case("obj_no_faces", M)(lambda f: write_obj(f, [x for x in obj_lines(f) if x.startswith("v ")]))
case("obj_degenerate", M)(lambda f: write_obj(f, [x for x in obj_lines(f) if x.startswith("v ")]
                                                  + ["f 1 1 1", "f 2 2 3", "f 4 5 4"]))
case("obj_face_index_0", M)(lambda f: write_obj(f, obj_lines(f) + ["f 0 1 2"]))
case("obj_face_index_huge", M)(lambda f: write_obj(f, obj_lines(f) + [f"f 1 2 {HUGE_INT}"]))
case("obj_face_index_2_63", M)(lambda f: write_obj(f, obj_lines(f) + [f"f 1 2 {2**63}"]))
case("obj_face_index_negative", M)(lambda f: write_obj(f, obj_lines(f) + ["f 1 2 -99999"]))
case("obj_face_two_vertices", M)(lambda f: write_obj(f, obj_lines(f) + ["f 1 2"]))
case("obj_vertex_nan", M)(lambda f: write_obj(f, ["v nan 0 0"] + obj_lines(f)))
case("obj_vertex_1e200", M)(lambda f: write_obj(f, ["v 1e200 0 0"] + obj_lines(f)[1:]))
case("obj_vertex_word", M)(lambda f: write_obj(f, ["v one 0 0"] + obj_lines(f)[1:]))
case("obj_fifo", M)(lambda f: replace_path(f / M, "fifo"))
case("obj_dir", M)(lambda f: replace_path(f / M, "dir"))
case("obj_dev_zero", M)(lambda f: replace_path(f / M, "zero"))
case("obj_tabs", None)(lambda f: write_obj(f, [x.replace(" ", "\t") for x in obj_lines(f)]))
case("obj_leading_spaces", None)(lambda f: write_obj(f, ["   " + x for x in obj_lines(f)]))
case("obj_bom", None)(lambda f: set_text(f / M, "\ufeff" + (f / M).read_text()))
case("obj_crlf", None)(lambda f: set_text(f / M, (f / M).read_text().replace("\n", "\r\n")))
case("two_meshes_no_manifest", ".")(
    lambda f: ((f / "rig.json").unlink(), shutil.copy(f / M, f / "other.obj")))
case("elk_two_parts_merge", None, "elk")(
    lambda f: ((f / "models" / "body.obj").rename(f / "models" / "a.obj"), write_obj_part(f)))


def write_obj_part(folder):
    """A second, separate part in models/ (a little box), as the elk exports have."""
    lines = [f"v {x} {y} {z}" for x in (1, 2) for y in (1, 2) for z in (1, 2)]
    lines += ["f 1 2 4 3", "f 5 7 8 6", "f 1 5 6 2", "f 3 4 8 7", "f 1 3 7 5", "f 2 6 8 4"]
    (folder / "models" / "b.obj").write_text("\n".join(lines) + "\n")


for _ext in ("ply", "stl", "vtk", "vtu", "vtp"):
    _m = f"mesh.{_ext}"
    case(f"{_ext}_empty", _m)(lambda f, m=_m: replace_mesh(f, m, b""))
    case(f"{_ext}_garbage", _m)(lambda f, m=_m: replace_mesh(f, m, GARBAGE))
    case(f"{_ext}_truncated", _m)(
        lambda f, m=_m, e=_ext: replace_mesh(f, m, mesh_bytes(e)[: len(mesh_bytes(e)) // 2]))
case("ply_ascii_huge_index", "mesh.ply")(lambda f: replace_mesh(f, "mesh.ply", (
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    f"0 0 0\n1 0 0\n0 1 0\n3 0 1 {HUGE_INT}\n").encode()))
case("ply_header_only", "mesh.ply")(lambda f: replace_mesh(f, "mesh.ply", (
    b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty float x\n"
    b"property float y\nproperty float z\nend_header\n")))
case("stl_zero_facets", "mesh.stl")(
    lambda f: replace_mesh(f, "mesh.stl", b"\0" * 80 + struct.pack("<I", 0)))
case("stl_claims_many", "mesh.stl")(
    lambda f: replace_mesh(f, "mesh.stl", b"\0" * 80 + struct.pack("<I", 2**31) + b"\0" * 100))

# ---------------------------------------------------------------------------- weights.npz
W = "weights.npz"
case("npz_empty", W)(lambda f: set_text(f / W, b"", "wb"))
case("npz_text", W)(lambda f: set_text(f / W, "not a zip"))
case("npz_garbage", W)(lambda f: set_text(f / W, GARBAGE, "wb"))
case("npz_truncated", W)(lambda f: set_text(f / W, (f / W).read_bytes()[:300], "wb"))
case("npz_no_arrays", W)(lambda f: set_text(f / W, npz_bytes(other=np.zeros(3)), "wb"))
case("npz_float_indices", W)(weights_edit(lambda a: a.__setitem__(
    "indices", a["indices"].astype(float) + 0.5)))
case("npz_negative_weights", W)(weights_edit(lambda a: a.__setitem__(
    "weights", a["weights"] * np.where(np.arange(a["weights"].shape[1]) == 1, -1, 3))))
case("npz_nan_weights", W)(weights_edit(lambda a: a["weights"].__setitem__((0, 0), np.nan)))
case("npz_zero_row", W)(weights_edit(lambda a: a["weights"].__setitem__(3, 0)))
case("npz_duplicate_joints", W)(weights_edit(lambda a: a.__setitem__(
    "joints", np.array(["j0", "j0", "j2"]))))
case("npz_joints_numbers", W)(weights_edit(lambda a: a.__setitem__("joints", np.arange(3))))
case("npz_index_range", W)(weights_edit(lambda a: a["indices"].__setitem__((0, 0), 99)))
case("npz_wrong_count", W)(weights_edit(lambda a: [a.__setitem__(k, a[k][:-5])
                                                     for k in ("indices", "weights")]))
case("npz_3d", W)(weights_edit(lambda a: [a.__setitem__(k, a[k][:, :, None])
                                            for k in ("indices", "weights")]))
case("npz_object", W)(weights_edit(lambda a: a.__setitem__(
    "joints", np.array([["j0"], "j1", 2], dtype=object))))
case("npz_fifo", W)(lambda f: replace_path(f / W, "fifo"))
case("npz_dir", W)(lambda f: replace_path(f / W, "dir"))
case("npz_dev_zero", W)(lambda f: replace_path(f / W, "zero"))


def huge_header_npz(folder):
    """An npz whose ``indices`` header claims 10^12 rows (4 TB) over a few bytes of data."""
    import io

    arrays = good_weights(folder)
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        for key in ("weights", "joints"):
            zf.writestr(f"{key}.npy", _npy(arrays[key]))
        hdr = io.BytesIO()
        np.lib.format.write_array_header_1_0(
            hdr, {"descr": "<i4", "fortran_order": False, "shape": (10**12, 4)})
        zf.writestr("indices.npy", hdr.getvalue() + b"\0" * 64)
    (folder / W).write_bytes(buf.getvalue())


def _npy(arr):
    import io

    b = io.BytesIO()
    np.save(b, arr)
    return b.getvalue()


case("npz_huge_header", W)(huge_header_npz)

# ---------------------------------------------------------------------------- other paths
case("animations_is_file", "animations")(
    lambda f: (shutil.rmtree(f / "animations"), set_text(f / "animations", "x")))


# ---------------------------------------------------------------------------- running
COMMANDS = {
    "info": ["info", "{rig}"],
    "list": ["list", "{rig}"],
    "weights": ["weights", "{rig}", "-o", "{out}/w.npz"],
    "render": ["render", "walk", "--rig", "{rig}", "-o", "{out}/x.gif", "--fps", "2",
               "--duration", "0.5", "-q"],
}
LOAD_SNIPPET = (
    "import sys, warnings, rigedit\n"
    "warnings.simplefilter('ignore')\n"
    "try:\n"
    "    rigedit.load_rig(sys.argv[1])\n"
    "except rigedit.RigFileError as exc:\n"
    "    print('RigFileError:', str(exc).replace(chr(10), '\\\\n'), file=sys.stderr)\n"
    "    sys.exit(2)\n")


def _limits():
    import resource

    gb = 6 * 2**30
    resource.setrlimit(resource.RLIMIT_AS, (gb, gb))


def classify(c, folder, rc, stderr, timed_out):
    """'good' or a short reason why the outcome is a bug."""
    if timed_out:
        return "hang"
    lines = [x for x in stderr.splitlines() if x.strip() and not x.startswith("rigedit: warning")]
    if "Traceback" in stderr:
        return "traceback"
    if not c.expect_error:
        return "good" if rc == 0 else f"rejected valid (rc {rc})"
    if rc == 0:
        return "accepted bad"
    if rc != 2:
        return f"exit {rc}"
    if len(lines) != 1:
        return f"{len(lines)} lines"
    culprit = str(folder / c.culprit)
    if culprit not in lines[0]:
        return "file not named"
    return "good"


def run_one(c, folder, command, out, timeout):
    import subprocess

    if command == "load_rig":
        argv = [sys.executable, "-c", LOAD_SNIPPET, str(folder)]
    else:
        argv = [sys.executable, "-m", "rigedit"] + [
            a.format(rig=folder, out=out) for a in COMMANDS[command]]
    env = dict(os.environ, PYTHONFAULTHANDLER="", OMP_NUM_THREADS="1")
    try:
        proc = subprocess.run(argv, capture_output=True, text=True, timeout=timeout,
                              preexec_fn=_limits, env=env, stdin=subprocess.DEVNULL,
                              errors="replace")
        return classify(c, folder, proc.returncode, proc.stderr, False), proc.stderr
    except subprocess.TimeoutExpired as exc:
        return "hang", str(exc.stderr or "")


def main(argv=None):
    import argparse
    from collections import Counter
    from concurrent.futures import ThreadPoolExecutor

    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("root", type=Path)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--timeout", type=float, default=30.0)
    p.add_argument("--no-render", action="store_true")
    p.add_argument("--only", default="", help="run the cases whose name contains this")
    args = p.parse_args(argv)
    out = args.root.with_name(args.root.name + "_out")
    out.mkdir(exist_ok=True)
    cases = [(c, f) for c, f in build_corpus(args.root) if args.only in c.name]
    commands = ["load_rig", "info", "list", "weights"] + ([] if args.no_render else ["render"])
    jobs = [(c, f, cmd) for c, f in cases for cmd in commands]
    with ThreadPoolExecutor(args.jobs) as pool:
        results = list(pool.map(lambda j: (j, run_one(j[0], j[1], j[2], out, args.timeout)),
                                jobs))
    counts = Counter()
    for (c, f, cmd), (verdict, err) in results:
        counts[verdict] += 1
        if verdict != "good":
            first = (err.strip().splitlines() or [""])[-1][:150]
            print(f"BUG {c.name:32s} {cmd:8s} {verdict:16s} {first}")
    print(f"{len(cases)} folders x {len(commands)} commands = {len(jobs)} runs: "
          + ", ".join(f"{k} {v}" for k, v in counts.most_common()))
    per_case = Counter(c.name for (c, f, cmd), (v, e) in results if v != "good")
    print(f"folders with at least one bad outcome: {len(per_case)} of {len(cases)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
