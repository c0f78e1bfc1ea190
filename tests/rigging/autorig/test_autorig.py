"""rigedit.autorig and `rigedit autorig`: the whole pipeline on meshes in foreign frames."""
from __future__ import annotations

from testpaths import REPO
import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

import rigedit
from rigedit.cli.main import main
from rigedit.errors import RigFileError
from rigedit.io.mesh import save_obj
from rigedit.model.skeleton import Skeleton
from rigedit.rigging.autorig.pipeline import build_skeleton, load_template

DATA = REPO.parent / "shared" / "data"
HOMER = DATA / "common-3d-test-models" / "homer.obj"

# The bundled humanoid's mesh as a file would bring it: Z up, facing -X, in centimetres,
# somewhere else. Input axis of each rigedit axis: rigedit +Y (up) is the input's +Z,
# rigedit +Z (forward) the input's -X, so rigedit +X (left) is the input's -Y.
TO_INPUT = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
SCALE, SHIFT = 100.0, np.array([250.0, -40.0, 13.0])


def _foreign(rig):
    return (rig.vertices @ TO_INPUT.T) * SCALE + SHIFT


@pytest.fixture(scope="module")
def human(humanoid):
    ref = humanoid
    rig = rigedit.autorig((_foreign(ref), ref.faces), template="humanoid")
    return ref, rig


def test_orientation_guessed_and_mesh_stood_on_the_floor(human):
    ref, rig = human
    rep = rig.autorig_report
    o = rep.orientation
    assert o.guessed and o.sure
    np.testing.assert_allclose(o.up, [0, 0, 1])
    np.testing.assert_allclose(o.forward, [-1, 0, 0])
    assert "up +z, forward -x (guessed)" in rep.lines()[0]
    # units kept (centimetres), standing on y = 0, centred over the origin in x and z
    lo, hi = rig.vertices.min(axis=0), rig.vertices.max(axis=0)
    assert lo[1] == pytest.approx(0.0, abs=1e-9)
    assert hi[1] == pytest.approx(SCALE * np.ptp(ref.vertices[:, 1]), rel=1e-9)
    assert (lo + hi)[[0, 2]] == pytest.approx([0.0, 0.0], abs=1e-6)
    # the reported transform maps the input onto the rig's mesh
    back = _foreign(ref) @ rep.transform[:3, :3].T + rep.transform[:3, 3]
    np.testing.assert_allclose(back, rig.vertices, atol=1e-9)


def test_joints_land_near_the_characters_own(human):
    """The embedded joints, in the rig's frame, against the shipped skeleton carried there
    by the reported transform (a pipeline check: a wrong turn or shift would be metres off)."""
    ref, rig = human
    from rigedit.embedding import cd_j2j

    m = rig.autorig_report.transform
    truth = (ref.skeleton.bind_matrices[:, :3, 3] @ TO_INPUT.T * SCALE + SHIFT) @ m[:3, :3].T \
        + m[:3, 3]
    ours = rig.skeleton.bind_matrices[:, :3, 3]
    diag = np.linalg.norm(np.ptp(rig.vertices, axis=0))
    assert cd_j2j(ours, truth, diag) < 4.0
    assert rig.skeleton.names == ref.skeleton.names
    assert np.array_equal(rig.skeleton.parents, ref.skeleton.parents)
    assert np.array_equal(rig.skeleton.deform, ref.skeleton.deform)


def test_clips_play_and_feet_reach_the_floor(human):
    ref, rig = human
    assert set(rig.clips) == set(ref.clips)
    assert set(rig.autorig_report.clips.values()) == {"retargeted"}
    walk = rig.clips["walk"]
    height = np.ptp(rig.vertices[:, 1])
    rest = rig.skin(rig.rest_pose())
    lows, moved = [], []
    for t in np.linspace(0, walk.duration, 12, endpoint=False):
        v = rig.skin(walk.sample(t))
        moved.append(np.linalg.norm(v - rest, axis=1).max())
        lows.append(v[:, 1].min())
    assert min(moved) > 0.02 * height          # the skin follows the clip
    lows = np.array(lows)
    # a foot is on the floor in every sample: not sunk, not floating
    assert np.all(np.abs(lows) < 0.03 * height), lows / height
    # and the character travels forward (+Z) over the cycle
    root = rig.skeleton.index["root"]
    start = rig.joint_matrices(walk.sample(0.0))[root, 2, 3]
    end = rig.joint_matrices(walk.sample(walk.duration * 0.999))[root, 2, 3]
    assert end - start > 0.2 * height


def test_weights_bind_every_vertex_to_nearby_bones(human):
    _, rig = human
    w = rig.weights
    np.testing.assert_allclose(np.asarray(w.sum(axis=1)).ravel(), 1.0, atol=1e-6)
    # the head's vertices follow the head, the feet's the legs
    top = np.argmax(rig.vertices[:, 1])
    names = rig.skeleton.names
    assert names[int(np.argmax(w[top].toarray()))] in ("Head", "Neck")
    low = np.argmin(rig.vertices[:, 1] - 1e-3 * rig.vertices[:, 0])
    assert "Foot" in names[int(np.argmax(w[low].toarray()))] or \
        "Toe" in names[int(np.argmax(w[low].toarray()))]


def test_saves_and_loads_as_folder_and_glb(human, tmp_path):
    _, rig = human
    for out in (tmp_path / "rig", tmp_path / "rig.glb"):
        rig.save(out)
        back = rigedit.load_rig(out)
        assert back.skeleton.names == rig.skeleton.names
        np.testing.assert_allclose(back.skeleton.bind_matrices, rig.skeleton.bind_matrices,
                                   atol=1e-4)
        assert set(back.clips) == set(rig.clips)
        pose = rig.clips["walk"].sample(0.4)
        np.testing.assert_allclose(back.skin(back.clips["walk"].sample(0.4)), rig.skin(pose),
                                   atol=1e-3 * SCALE)
    script = os.environ.get("RIGEDIT_GLTF_VALIDATOR")
    if script and Path(script).is_file() and shutil.which("node"):
        run = subprocess.run(["node", script, str(tmp_path / "rig.glb")], capture_output=True,
                             text=True, timeout=120)
        issues = json.loads(run.stdout)["issues"]
        assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, issues["messages"][:5]


def test_frames_are_the_templates_turned_by_the_smallest_swing():
    """A chain bent at its middle joint: each joint's model rotation is the template's turned
    by the rotation taking its template bone onto the new one about their common normal;
    a leaf keeps its parent's turn, the root the template's frame."""
    tmpl = Skeleton(["root", "a", "b", "c"], [-1, 0, 1, 2],
                    [[0, 0, 0], [0, 1, 0], [0, 1, 0], [0, 1, 0]],
                    rest_rotation=Rotation.from_euler("x", [[0], [10], [0], [0]], degrees=True).as_quat())
    rest = tmpl.forward(tmpl.rest_local_matrices())
    pos = rest[:, :3, 3].copy() * 2.0
    pos[3] = pos[2] + 2.0 * np.array([1.0, 0.0, 0.0])   # bend the last bone to +X
    sk = build_skeleton(tmpl, pos)
    model = sk.forward(sk.rest_local_matrices())
    np.testing.assert_allclose(model[:, :3, 3], pos, atol=1e-12)
    np.testing.assert_allclose(model[0, :3, :3], rest[0, :3, :3], atol=1e-12)
    np.testing.assert_allclose(model[1, :3, :3], rest[1, :3, :3], atol=1e-12)  # same direction
    a = rest[3, :3, 3] - rest[2, :3, 3]
    b = pos[3] - pos[2]
    swing = model[2, :3, :3] @ rest[2, :3, :3].T
    np.testing.assert_allclose(swing @ (a / np.linalg.norm(a)), b / np.linalg.norm(b), atol=1e-12)
    axis = Rotation.from_matrix(swing).as_rotvec()
    assert abs(axis @ a) < 1e-9 and abs(axis @ b) < 1e-9     # about the common normal only
    np.testing.assert_allclose(model[3, :3, :3] @ rest[3, :3, :3].T, swing, atol=1e-12)


def test_template_that_is_not_a_skeleton(tmp_path):
    mesh = tmp_path / "body.obj"
    save_obj(mesh, np.eye(3), [[0, 1, 2]])
    with pytest.raises(RigFileError, match="body.obj: expected a template skeleton"):
        load_template(mesh)
    bad = tmp_path / "weights.json"
    bad.write_text(json.dumps({"indices": [1, 2]}))
    with pytest.raises(RigFileError, match="weights.json: expected a 'joints' field"):
        load_template(bad)
    two = Skeleton(["a", "b"], [-1, 0], [[0, 0, 0], [0, 1, 0]])
    with pytest.raises(RigFileError, match="got 2 joints"):
        load_template(two)


def _run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_errors_name_the_file(tmp_path, capsys, humanoid):
    ref = humanoid
    # a mesh with no volume: the body's front half, a shell without a back
    keep = ref.vertices[ref.faces].mean(axis=1)[:, 2] > 0.0
    open_mesh = tmp_path / "open.obj"
    save_obj(open_mesh, ref.vertices, ref.faces[keep])
    code, out, err = _run(["autorig", str(open_mesh), "-o", str(tmp_path / "o.glb")], capsys)
    assert code == 2 and err.count("\n") == 1
    assert err.startswith(f"rigedit: error: {open_mesh}: no volume") and "hole" in err
    assert "an open shell or sheet" in err
    # a point cloud
    cloud = tmp_path / "cloud.ply"
    cloud.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                     "property float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n")
    code, out, err = _run(["autorig", str(cloud), "-o", str(tmp_path / "o.glb")], capsys)
    assert code == 2 and f"{cloud}: " in err and "point cloud" in err
    # axes that are not at right angles, a template that is not a skeleton
    code, _, err = _run(["autorig", str(open_mesh), "--up", "y", "--forward=-y", "-o",
                         str(tmp_path / "o.glb")], capsys)
    assert code == 2 and err == ("rigedit: error: expected --up and --forward at right angles, "
                                 "got up +y and forward -y\n")
    code, _, err = _run(["autorig", str(open_mesh), "--up", "north", "-o",
                         str(tmp_path / "o.glb")], capsys)
    assert code == 2 and "expected an axis such as y, -x or +z, got 'north'" in err
    code, _, err = _run(["autorig", str(cloud), "--template", str(open_mesh), "-o",
                         str(tmp_path / "o.glb")], capsys)
    assert code == 2 and f"{open_mesh}: expected a template skeleton" in err
    assert not (tmp_path / "o.glb").exists()


def test_cli_blob_without_limbs(tmp_path, capsys):
    """An elongated blob is closed but has nothing like legs or arms."""
    rng = np.random.default_rng(0)
    p = rng.normal(size=(800, 3))
    p = p / np.linalg.norm(p, axis=1, keepdims=True) * [0.3, 0.9, 0.2]
    blob = tmp_path / "blob.obj"
    save_obj(blob, p, ConvexHull(p).simplices)
    code, _, err = _run(["autorig", str(blob), "--up", "y", "--forward", "z", "-o",
                         str(tmp_path / "o")], capsys)
    assert code == 2 and err.count("\n") == 1
    assert err.startswith(f"rigedit: error: {blob}: no place found for the template's")
    assert not (tmp_path / "o").exists()


def test_cli_homer_prints_orientation_checks_and_times(tmp_path, capsys):
    if not HOMER.is_file():
        pytest.skip(f"{HOMER} is absent (shared test data)")
    out_dir = tmp_path / "homer"
    code, out, err = _run(["autorig", str(HOMER), "-o", str(out_dir)], capsys)
    assert code == 0, err
    lines = out.splitlines()
    assert lines[0] == "orientation: up +y, forward +z (guessed)"
    assert "holes: closed (no holes)" in lines
    times = next(line for line in lines if line.startswith("seconds: "))
    for stage in ("load/check", "orient", "embedding", "weights", "clips", "total"):
        assert f"{stage} " in times
    rig = rigedit.load_rig(out_dir)
    assert set(rig.clips) == {"idle", "walk", "wave"}
    # homer stands on y = 0 in his own units (0.84 high) and his head is up
    assert rig.vertices[:, 1].min() == pytest.approx(0.0, abs=1e-6)
    head = rig.skeleton.bind_matrices[rig.skeleton.index["Head"], 1, 3]
    foot = rig.skeleton.bind_matrices[rig.skeleton.index["LeftFoot"], 1, 3]
    assert head > 0.7 * np.ptp(rig.vertices[:, 1]) > foot


def test_progress_reports_stages_in_order_and_a_raise_cancels(humanoid):
    ref = humanoid
    seen = []

    class Cancelled(Exception):
        pass

    def progress(fraction, stage):
        seen.append((fraction, stage))
        if stage == "embedding" and fraction > 0.2:
            raise Cancelled

    with pytest.raises(Cancelled):
        rigedit.autorig((ref.vertices, ref.faces), up="y", forward="z", progress=progress)
    stages = [s for _, s in seen]
    assert stages[0] == "load/check" and "orient" in stages and stages[-1] == "embedding"
    fractions = [f for f, _ in seen]
    assert fractions == sorted(fractions) and 0.0 <= fractions[0] and fractions[-1] < 0.6


def test_skeleton_file_template_without_clips(tmp_path, humanoid):
    """A bare skeleton file: names and hierarchy come along, no clips (it has none)."""
    if not HOMER.is_file():
        pytest.skip(f"{HOMER} is absent (shared test data)")
    from rigedit.io.skeleton_json import save_skeleton

    ref = humanoid
    path = tmp_path / "skeleton.json"
    save_skeleton(path, ref.skeleton)
    rig = rigedit.autorig(HOMER, template=path, weights="idw")
    assert rig.skeleton.names == ref.skeleton.names and rig.clips == {}
    assert rig.autorig_report.template == str(path)
    # homer stands the right way up in the skeleton (his head starts at about two thirds
    # of his height), feet at the bottom, his left hand on +X
    pos = rig.skeleton.bind_matrices[:, :3, 3]
    sk = rig.skeleton
    height = np.ptp(rig.vertices[:, 1])
    y = {n: pos[sk.index[n], 1] for n in ("Head", "LeftArm", "Hips", "LeftLeg", "LeftFoot")}
    assert y["Head"] > y["LeftArm"] > y["Hips"] > y["LeftLeg"] > y["LeftFoot"]
    assert y["Head"] > 0.55 * height and y["LeftFoot"] < 0.15 * height
    assert pos[sk.index["LeftHand"], 0] > 0 > pos[sk.index["RightHand"], 0]


def test_cow_as_a_quadruped_walks():
    """cow.obj faces +X with +Y up: guessed, embedded with the quadruped template, and the
    template's walk retargeted: hooves low, head forward, feet on the floor while it walks."""
    cow = DATA / "common-3d-test-models" / "cow.obj"
    if not cow.is_file():
        pytest.skip(f"{cow} is absent (shared test data)")
    rig = rigedit.autorig(cow, template="quadruped")
    o = rig.autorig_report.orientation
    assert o.sure and o.describe() == "up +y, forward +x (guessed)"
    assert set(rig.autorig_report.clips.values()) == {"retargeted"}
    sk = rig.skeleton
    pos = sk.bind_matrices[:, :3, 3]
    height = np.ptp(rig.vertices[:, 1])
    hooves = [sk.index[f"{leg}_hoof_{s}"] for leg in ("fore", "hind") for s in "LR"]
    assert pos[hooves, 1].max() < 0.15 * height
    assert pos[sk.index["head"], 2] > pos[sk.index["pelvis"], 2] + 0.3 * height
    assert pos[sk.index["fore_hoof_L"], 0] > 0 > pos[sk.index["fore_hoof_R"], 0]
    walk = rig.clips["walk"]
    rest = rig.skin(rig.rest_pose())
    for t in np.linspace(0, walk.duration, 8, endpoint=False):
        v = rig.skin(walk.sample(t))
        assert abs(v[:, 1].min()) < 0.04 * height
        assert np.linalg.norm(v - rest, axis=1).max() > 0.02 * height


def test_bvh_template_lying_at_rest_is_stood_up_from_its_first_frame():
    """Bandai's BVH rest lies along one axis: the template pose embedded is the first frame
    of its clip, turned to face +Z, standing (head over the feet, toes forward)."""
    bvh = DATA / "bvh-bandai" / "dataset-1_walk_normal_002.bvh"
    if not bvh.is_file():
        pytest.skip(f"{bvh} is absent (shared test data)")
    import warnings

    from rigedit.rigging.autorig.pipeline import template_poses

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # the BVH's guessed units
        rig, sk, name = load_template(bvh)
    poses = template_poses(sk, rig, name)
    posed, source = poses[0]
    assert source.startswith("frame 0 of ")
    p = posed.forward(posed.rest_local_matrices())[:, :3, 3]
    height = np.ptp(p[:, 1])
    names = posed.names
    head = p[[i for i, n in enumerate(names) if "head" in n.lower()][0]]
    toes = [i for i, n in enumerate(names) if "toe" in n.lower()]
    feet = [posed.parents[i] for i in toes]
    assert head[1] - p[feet, 1].mean() > 0.7 * height          # standing up
    assert np.all(p[toes, 2] > p[feet, 2])                       # toes point to +Z
    # the mesh template keeps its rest, nothing else to try
    human = rigedit.load_rig("humanoid")
    assert [s for _, s in template_poses(human.skeleton, human, "humanoid")] == ["rest"]


def test_leaf_tails_follow_the_rest_pose_when_the_template_binds_elsewhere():
    """A glTF template may bind its mesh in another frame than its rest (CesiumMan binds Z
    up): a leaf's tail, given at bind time, is carried to the rest pose before it is moved
    with the embedded joint. Embedded exactly at the template's rest joints, every tail must
    land where the rest pose carries it."""
    rest_rot = Rotation.from_euler("x", [[0], [0], [0]], degrees=True).as_quat()
    plain = Skeleton(["r", "a", "b"], [-1, 0, 1], [[0, 0, 0], [0, 1, 0], [0, 1, 0]],
                     rest_rotation=rest_rot)
    rest = plain.forward(plain.rest_local_matrices())
    bind = rest.copy()
    turn = np.eye(4)
    turn[:3, :3] = Rotation.from_euler("x", 90, degrees=True).as_matrix()
    bind = turn @ bind                                    # bound lying down, Z up
    tails = np.full((3, 3), np.nan)
    tails[2] = (turn @ np.r_[0.0, 2.5, 0.0, 1.0])[:3]      # 0.5 above b, in the bind frame
    tmpl = Skeleton(["r", "a", "b"], [-1, 0, 1], [[0, 0, 0], [0, 1, 0], [0, 1, 0]],
                    rest_rotation=rest_rot, bind_matrices=bind, tails=tails)
    sk = build_skeleton(tmpl, rest[:, :3, 3])
    np.testing.assert_allclose(sk.tails[2], [0.0, 2.5, 0.0], atol=1e-12)


def test_array_input_is_checked():
    with pytest.raises(ValueError, match=r"mesh: expected finite vertices of shape \(V, 3\)"):
        rigedit.autorig((np.zeros((4, 2)), [[0, 1, 2]]))
    with pytest.raises(ValueError, match="mesh: expected faces .* below 3"):
        rigedit.autorig((np.eye(3), [[0, 1, 3]]))
    with pytest.raises(RigFileError, match="mesh: expected a surface mesh, got no faces"):
        rigedit.autorig((np.eye(3), np.zeros((0, 3), int)))


def test_glb_mesh_keeps_its_texture_coordinates_and_materials(tmp_path):
    cesium = DATA / "khronos-gltf" / "CesiumMan.glb"
    if not cesium.is_file():
        pytest.skip(f"{cesium} is absent (shared test data)")
    src = rigedit.load_rig(cesium)
    rig = rigedit.autorig(cesium, clips=False)
    assert rig.autorig_report.orientation.describe() == "up +y, forward +z (guessed)"
    assert len(rig.vertices) == len(src.vertices)         # seams kept, as the file has them
    np.testing.assert_array_equal(rig.surface.uvs, src.surface.uvs)
    assert rig.surface.textured_material() is not None and rig.surface.normals is None
    back = rigedit.load_rig(rig.save(tmp_path / "cesium.glb"))
    np.testing.assert_allclose(back.surface.uvs, src.surface.uvs, atol=1e-6)
