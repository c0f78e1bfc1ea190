"""FBX in (rigedit/io/fbx_read.py) against the ufbx project's reference meshes: each OBJ is
the skinned mesh at a stated take and time, in the FBX file's own units and axes, made by the
program that wrote the FBX file (not by rigedit, not by ufbx's skinning)."""
import struct
import subprocess
import sys
import warnings

import numpy as np
import pytest
from scipy.spatial import cKDTree

from fbx_mini import mini_fbx
from rigedit.cli.main import main
from rigedit.errors import RigFileError
from rigedit.io.fbx_read import read_fbx
from rigedit.io.fbx_read_anim import reduce_keys
from rigedit.io.fbx_read_limits import check_claims
from rigedit.io.fbx_read_scene import opened
from rigedit.rig import Rig
from testpaths import DATA

UFBX = DATA / "fbx" / "ufbx"
MIXAMO = DATA / "fbx" / "mixamo.fbx"

# (fbx, reference obj, take, seconds in the file's time)
REFERENCES = [
    ("blender_279_sausage_6100_ascii.fbx", "blender_279_sausage_base_0.obj", "Base", 0.0),
    ("blender_279_sausage_6100_ascii.fbx", "blender_279_sausage_spin_15.obj", "Spin", 15 / 24),
    # Blender numbers frames from 1: its frame 20 of the Wiggle take (which starts at 0 s)
    # is 19/24 s; at 20/24 s the mesh is elsewhere (half its diagonal)
    ("blender_279_sausage_6100_ascii.fbx", "blender_279_sausage_wiggle_20.obj", "Wiggle",
     19 / 24),
    ("max7_skin_5000_binary.fbx", "max7_skin_5.obj", "Take 001", 5 / 30),
    ("max7_skin_5000_binary.fbx", "max7_skin_15.obj", "Take 001", 15 / 30),
    ("max_transformed_skin_7500_ascii.fbx", "max_transformed_skin_5.obj", "Take 001", 5 / 30),
    ("max_transformed_skin_7500_ascii.fbx", "max_transformed_skin_15.obj", "Take 001", 15 / 30),
    ("maya_game_sausage_7500_binary_wiggle.fbx", "maya_game_sausage_wiggle_10.obj", "wiggle",
     10 / 24),
    ("maya_game_sausage_7500_binary_wiggle.fbx", "maya_game_sausage_wiggle_18.obj", "wiggle",
     18 / 24),
] + [("motionbuilder_sausage_rrss_7700_binary.fbx",
      f"motionbuilder_sausage_rrss{'' if k == 0 else f'_{k}'}.obj", "Take 001", k / 24)
     for k in (0, 12, 24, 36, 48)]
# Not used: maya_transformed_skin_*.obj ("ufbx:transform_skin": ufbx's test harness moves the
# skin before comparing), maya_dq_weights_*.obj (Maya's per-vertex blend of linear and
# dual-quaternion skinning, which rigedit does not have), maya_human_ik (no mesh).


def _need(*paths):
    for p in paths:
        if not p.exists():
            pytest.skip(f"missing test data {p}")


def _file_frame(fbx):
    """(3, 3) map from the file's coordinates to rigedit's (metres, Y up, +Z forward), and
    each take's start, from the file's own settings (ufbx without conversion)."""
    # ufbx's objects through fbx_read_scene's holder (each fetched once, freed in order)
    with opened(fbx) as converted:
        starts = {s.name: s.time_begin for s in converted.anim_stacks}
    with opened(fbx, convert=False) as scene:          # as the file is
        unit, axes = scene.settings.unit_meters, scene.settings.axes
    unit_vector = {0: (1, 0, 0), 1: (-1, 0, 0), 2: (0, 1, 0), 3: (0, -1, 0), 4: (0, 0, 1),
                   5: (0, 0, -1)}
    right, up, front = (int(a) for a in (axes.right, axes.up, axes.front))
    if right > 5 or up > 5 or front > 5:      # FBX 5 states no axes: Y up as ufbx reads it
        right, up, front = 0, 2, 4
    basis = np.array([unit_vector[right], unit_vector[up], unit_vector[front]], float)
    return unit * basis, starts


def _obj(path):
    lines = path.read_text().splitlines()
    points = np.array([[float(x) for x in line.split()[1:4]] for line in lines
                       if line.startswith("v ")])
    stated = [float(line.split("=", 1)[1]) for line in lines
              if line.startswith("# ufbx:tolerance=")]
    return points, (stated[0] if stated else 0.0)


_RIGS = {}


def _rig(fbx):
    if fbx not in _RIGS:
        with warnings.catch_warnings():
            warnings.simplefilter("error")          # these files read without a warning
            # but for MotionBuilder's strings that are not UTF-8, which ufbx repairs
            warnings.filterwarnings("ignore", message=".*ufbx repaired 1 kind of problem")
            data = read_fbx(UFBX / fbx)
        _RIGS[fbx] = (data, Rig.from_data(data))
    return _RIGS[fbx]


@pytest.mark.parametrize("fbx,obj,take,seconds", REFERENCES,
                         ids=[r[1].removesuffix(".obj") for r in REFERENCES])
def test_skinned_mesh_matches_the_reference(fbx, obj, take, seconds):
    _need(UFBX / fbx, UFBX / obj)
    data, rig = _rig(fbx)
    frame, starts = _file_frame(UFBX / fbx)
    ref, stated = _obj(UFBX / obj)
    ref = ref @ frame.T
    diag = np.linalg.norm(ref.max(axis=0) - ref.min(axis=0))
    # a take that starts before 0 s is shifted to 0 (said in meta.notes)
    t = seconds + max(0.0, -starts[take])
    posed = rig.skin(data.clips[take].sample(t))
    # every reference vertex has a vertex here and every vertex here one there (rigedit
    # splits vertices where normals or UVs differ, and the 3ds Max OBJ files are reordered)
    error = max(cKDTree(posed).query(ref)[0].max(), cKDTree(ref).query(posed)[0].max())
    # the 3ds Max references state their own tolerance (0.01 file units, about 5e-4 of the
    # diagonal): rigedit is within 6e-5 of the diagonal of them
    tol = max(1e-5 * diag, stated * np.abs(frame).max())
    assert error <= tol, f"{error / diag:.2e} of the diagonal"
    # and the pose is not the rest pose where the reference moved
    rest = rig.skin(rig.rest_pose())
    if cKDTree(rest).query(ref)[0].max() > 10 * tol:
        assert np.abs(posed - rest).max() > 10 * tol


def test_mixamo_skeleton_weights_and_clips():
    _need(MIXAMO)
    data = read_fbx(MIXAMO)
    sk = data.skeleton
    assert len(sk) == 65 and sk.names[0] == "mixamorig:Hips"
    assert all(n.startswith("mixamorig:") for n in sk.names)
    assert sk.parents[sk.index["mixamorig:Spine"]] == sk.index["mixamorig:Hips"]
    assert sk.deform.sum() == 65                      # every limb node has a cluster
    assert data.vertices.shape == (28374, 3) and data.faces.shape == (49112, 3)
    assert data.indices.shape == (28374, 3) and np.all(data.weights >= 0)
    assert np.allclose(data.weights.sum(axis=1), 1.0, atol=1e-5)
    # centimetres in the file, metres here: a 1.8 m character standing on the ground
    height = data.vertices[:, 1].max() - data.vertices[:, 1].min()
    assert 1.7 < height < 1.9 and abs(data.vertices[:, 1].min()) < 0.01
    assert "centimetres" in data.meta.notes["units"] and data.meta.format == "fbx"
    assert set(data.clips) == {"Take 001", "mixamo.com"}
    clip = data.clips["mixamo.com"]
    assert abs(clip.duration - 16.8333) < 1e-3 and len(clip.tracks) > 60
    assert len(data.surface.materials) == 2 and data.surface.normals.shape == (28374, 3)
    assert data.surface.uvs.shape == (28374, 2)
    rig = Rig.from_data(data)
    a, b = rig.skin(clip.sample(1.0)), rig.skin(clip.sample(2.0))
    assert np.abs(a - b).max() > 0.05                 # the clip moves the character
    assert np.all(np.isfinite(a))


def test_skeleton_and_motion_without_a_mesh():
    path = UFBX / "maya_human_ik_7400_binary.fbx"
    _need(path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")        # no "computed weights" for a mesh-less rig
        rig = Rig.from_data(read_fbx(path))
    assert len(rig.vertices) == 0 and len(rig.skeleton) == 62 and rig.skeleton.deform.all()
    clip = rig.clips["Take 001"]
    assert abs(clip.duration - 5.0) < 1e-6 and len(clip.tracks) > 60
    # its take keys the HumanIK control rig, which only Maya solves: the limb nodes keep
    # their pose; in metres, the head's joints 1.5-1.8 m above the floor
    heads = rig.joint_matrices(clip.sample(2.5))[:, :3, 3]
    assert 1.5 < heads[:, 1].max() < 1.8 and abs(heads[:, 1].min()) < 0.1


def test_reading_twice_in_one_process():
    # the ufbx binding crashes when a freed wrapper is fetched again; every read holds its
    # wrappers until it ends
    _need(MIXAMO)
    first, second = read_fbx(MIXAMO), read_fbx(MIXAMO)
    assert np.array_equal(first.vertices, second.vertices)


def test_many_reads_in_one_process_never_crash():
    # the binding's reference counts are wrong; before every wrapper was pinned, four reads
    # of mixamo.fbx and a collection crashed about one process in ten, at random
    _need(MIXAMO)
    code = ("import gc, warnings; warnings.simplefilter('ignore')\n"
            "from rigedit.io.fbx_read import read_fbx\n"
            f"for _ in range(6):\n    read_fbx({str(MIXAMO)!r}); gc.collect()\n"
            "print('ok')")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0 and proc.stdout.strip() == "ok", proc.stderr[-500:]


def test_key_reduction_is_exact():
    rng = np.random.default_rng(1)
    for _ in range(200):
        n = int(rng.integers(2, 40))
        times = np.cumsum(rng.uniform(0.01, 0.1, n))
        steps = rng.choice([0.0, 0.0, 1.0], (n, 1)) * rng.normal(size=(n, 1))
        values = np.cumsum(steps, axis=0) + times[:, None] * rng.integers(0, 2)
        values = np.concatenate([values, 2 * values, np.zeros_like(values)], axis=1)
        keep = reduce_keys("translation", times, values)
        again = np.stack([np.interp(times, times[keep], values[keep, c]) for c in range(3)], 1)
        assert np.abs(again - values).max() <= 1e-9
    line = np.linspace(0, 1, 30)[:, None] * np.ones((1, 3))
    assert list(reduce_keys("translation", np.linspace(0, 1, 30), line)) == [0, 29]



def test_blend_shape_is_a_morph_target_with_its_weight_curve(tmp_path):
    path = tmp_path / "quad.fbx"
    path.write_text(mini_fbx([(0.0, 0.0), (0.5, 100.0), (1.0, 40.0)]))
    data = read_fbx(path)
    morphs = data.morphs
    assert morphs.names == ("Raise",) and np.allclose(morphs.default_weights, [0.25])
    clip = data.clips["Take 001"]
    track = clip.morph_tracks["Raise"]
    assert np.allclose(track.times, [0, 0.5, 1]) and np.allclose(track.values, [0, 1, 0.4])
    rig = Rig.from_data(data)
    corners = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    lift = np.array([[0, 0, 0], [0, 0, 0], [0, 0, 0.5], [0, 0, 0.5]])
    for t, w in [(0.0, 0.0), (0.25, 0.5), (0.5, 1.0), (0.75, 0.7), (1.0, 0.4)]:
        weights = clip.sample_morphs(t)
        assert abs(weights["Raise"] - w) < 1e-9
        posed = rig.skin(clip.sample(t), morph_weights=weights)
        # each vertex (split or not) is a corner plus w times its offset, in metres
        expected = corners + w * lift
        assert cKDTree(expected).query(posed)[0].max() < 1e-6
        assert cKDTree(posed).query(expected)[0].max() < 1e-6


def test_a_sparse_curve_is_baked_at_every_frame(tmp_path):
    # a cubic DeformPercent curve keyed at 0, 10 and 20 s: ufbx's default bake takes 30
    # samples per key interval; the file's 24 fps is asked for, so every frame is a key
    path = tmp_path / "cubic.fbx"
    path.write_text(mini_fbx([(0.0, 0.0), (10.0, 100.0), (20.0, 0.0)])
                    .replace("a: 260", "a: 1032"))          # KeyAttrFlags: cubic, auto
    clip = read_fbx(path).clips["Take 001"]
    frames = np.round(clip.morph_tracks["Raise"].times * 24)
    assert len(frames) > 470 and np.allclose(frames, clip.morph_tracks["Raise"].times * 24)
    # and at every frame the clip's weight is the curve's (ufbx evaluates it)
    import ufbx
    from rigedit.io.fbx_read_scene import call
    with opened(path) as scene:
        curve = scene.anim_curves[0]
        expected = [call(ufbx.evaluate_curve, curve, k / 24, 0.0, keep=scene._keep) / 100
                    for k in range(0, 20 * 24 + 1, 7)]
    for k, value in zip(range(0, 20 * 24 + 1, 7), expected):
        assert abs(clip.sample_morphs(k / 24)["Raise"] - value) < 1e-6


@pytest.mark.parametrize("keys,edit,message", [
    ([(0.0, 0.0), (1e7, 100.0)], None, "animation times within"),
    # a cubic curve over 10 days at 24 fps: 21 million keys to bake
    ([(0.0, 0.0), (5e5, 100.0), (9e5, 0.0)], ("a: 260", "a: 1032"), "keys to bake"),
    ([(0.0, 0.0), (1.0, 0.0)], ("a: 0,0,0,100,0,0", "a: 0,0,0,1e300,0,0"), r"at most 1e\+09"),
    ([(0.0, 0.0), (1.0, 0.0)], ("a: 0,0,0,100,0,0", "a: 0,0,0,nan,0,0"), "finite"),
])
def test_claims_beyond_the_bounds_are_one_error(tmp_path, keys, edit, message):
    path = tmp_path / "claim.fbx"
    text = mini_fbx(keys)
    path.write_text(text if edit is None else text.replace(*edit))
    with pytest.raises(RigFileError, match=message) as err:
        read_fbx(path)
    assert err.value.path == str(path)


def _png(path):
    import imageio.v3 as iio
    iio.imwrite(path, np.full((4, 4, 3), [10, 200, 30], np.uint8))


def test_texture_beside_the_file_is_read_and_outside_it_is_not(tmp_path):
    folder = tmp_path / "asset"
    folder.mkdir()
    _png(folder / "skin.png")
    _png(tmp_path / "secret.png")
    inside = folder / "in.fbx"
    inside.write_text(mini_fbx([(0.0, 0.0), (1.0, 0.0)], texture="skin.png"))
    [material] = read_fbx(inside).surface.materials
    assert material.texture is not None and tuple(material.texture[0, 0]) == (10, 200, 30, 255)
    for name in ("../secret.png", str(tmp_path / "secret.png")):
        outside = folder / "out.fbx"
        outside.write_text(mini_fbx([(0.0, 0.0), (1.0, 0.0)], texture=name))
        with pytest.warns(UserWarning, match="neither embedded nor in the file's folder"):
            [material] = read_fbx(outside).surface.materials
        assert material.texture is None and material.image_bytes is None


def _binary(tmp_path, mutate, name):
    data = bytearray(MIXAMO.read_bytes())
    mutate(data)
    path = tmp_path / name
    path.write_bytes(bytes(data))
    return path


@pytest.mark.parametrize("cut", [0.01, 0.3, 0.5, 0.99])
def test_truncated_file_is_one_error_naming_it(tmp_path, cut):
    _need(MIXAMO)
    size = MIXAMO.stat().st_size
    path = tmp_path / "cut.fbx"
    path.write_bytes(MIXAMO.read_bytes()[:int(size * cut)])
    with pytest.raises(RigFileError) as err:
        read_fbx(path)
    assert err.value.path == str(path) and "\n" not in str(err.value)


def test_byte_flips_load_or_are_one_error(tmp_path):
    _need(MIXAMO)
    rng = np.random.default_rng(7)
    errors = 0
    for k in range(12):
        offsets = rng.integers(27, MIXAMO.stat().st_size, 8)

        def flip(data, offsets=offsets):
            for o in offsets:
                data[o] ^= 0xFF
        path = _binary(tmp_path, flip, f"flip{k}.fbx")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                read_fbx(path)
        except RigFileError as exc:
            assert exc.path == str(path) and "\n" not in str(exc)
            errors += 1
    # a record offset flipped (the first record's end) is always an error
    path = _binary(tmp_path, lambda d: d.__setitem__(slice(27, 31), b"\xff\xff\xff\x7f"),
                   "offset.fbx")
    with pytest.raises(RigFileError):
        read_fbx(path)


def test_array_claiming_more_than_its_bytes_is_refused(tmp_path):
    _need(MIXAMO)
    data = MIXAMO.read_bytes()
    at = data.index(b"Vertices") + len(b"Vertices")
    assert data[at:at + 1] == b"d"

    def claim(d):
        struct.pack_into("<I", d, at + 1, 2**31 - 1)     # 16 GiB of doubles in 180 kB
    path = _binary(tmp_path, claim, "claim.fbx")
    with pytest.raises(RigFileError, match="compressed array"):
        check_claims(path.read_bytes(), path)
    with pytest.raises(RigFileError):
        read_fbx(path)


def test_not_fbx_and_no_skeleton(tmp_path):
    text = tmp_path / "text.fbx"
    text.write_text("hello\n")
    with pytest.raises(RigFileError) as err:
        read_fbx(text)
    assert err.value.path == str(text)
    fifo = tmp_path / "pipe.fbx"
    import os
    os.mkfifo(fifo)
    with pytest.raises(RigFileError, match="FIFO"):
        read_fbx(fifo)


def test_cli_info_of_an_fbx_file(capsys):
    _need(MIXAMO)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["info", str(MIXAMO)]) == 0
    out = dict(line.split(": ", 1) for line in capsys.readouterr().out.splitlines()
               if ": " in line)
    assert out["joints"] == "65" and out["vertices"] == "28374"
    assert out["clips"].split() == ["Take", "001", "mixamo.com"]
    assert "metres" in out["units"]


def test_cli_damaged_fbx_is_one_line_exit_2(tmp_path):
    _need(MIXAMO)
    path = tmp_path / "cut.fbx"
    path.write_bytes(MIXAMO.read_bytes()[:100000])
    proc = subprocess.run([sys.executable, "-m", "rigedit", "info", str(path)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    lines = [line for line in proc.stderr.splitlines() if line.startswith("rigedit: error")]
    assert len(lines) == 1 and str(path) in lines[0]
