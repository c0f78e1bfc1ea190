"""Skeleton embedding (rigedit.embedding): accuracy by CD-J2J, invariance, bad input, cancel.

Limits are about 1.5 times what was measured on this machine (the measured value is noted
beside each); the issue's targets are under 2% on the bundled characters' own meshes and at
most 4% on every test mesh. Heavy inputs are built once per module.
"""
from __future__ import annotations

from testpaths import REPO
from pathlib import Path

import numpy as np
import pytest

import rigedit
from rigedit.embedding import Embedding, EmbeddingError, cd_j2j, embed_skeleton

DATA = REPO.parent / "shared" / "data"


# ------------------------------------------------------------------------------ helpers
def _diagonal(vertices):
    return float(np.linalg.norm(np.ptp(vertices, axis=0)))


def _posed(rig, angles):
    """The rig skinned in a pose (Euler degrees per joint) and its joints, feet on the floor."""
    from test_embedding_stretch import stretched  # it imports this module's tables

    return stretched(rig, angles=angles)


def _subdivide(vertices, faces):
    """One midpoint subdivision (each triangle into four), shared edge midpoints."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), 1)
    unique, inverse = np.unique(edges, axis=0, return_inverse=True)
    mid = len(vertices) + inverse.reshape(3, -1).T                     # (F, 3): ab, bc, ca
    out_v = np.concatenate([vertices, vertices[unique].mean(axis=1)])
    a, b, c = faces.T
    ab, bc, ca = mid.T
    out_f = np.concatenate([np.c_[a, ab, ca], np.c_[ab, b, bc], np.c_[ca, bc, c], np.c_[ab, bc, ca]])
    return out_v, out_f


def _uv_sphere(n=32, m=16):
    theta = np.linspace(0, np.pi, m + 1)[1:-1]
    phi = np.linspace(0, 2 * np.pi, n, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring = np.c_[(np.sin(t) * np.cos(p)).ravel(), np.cos(t).ravel(), (np.sin(t) * np.sin(p)).ravel()]
    v = np.concatenate([[[0, 1.0, 0]], ring, [[0, -1.0, 0]]])
    f = [[0, 1 + (j + 1) % n, 1 + j] for j in range(n)]
    for i in range(m - 2):
        for j in range(n):
            a, b = 1 + i * n + j, 1 + i * n + (j + 1) % n
            f += [[a, b, b + n], [a, b + n, a + n]]
    base, last = 1 + (m - 2) * n, len(v) - 1
    f += [[last, base + j, base + (j + 1) % n] for j in range(n)]
    return v, np.array(f)


def _box(sx, sy, sz):
    v = np.array([[x, y, z] for x in (-sx / 2, sx / 2) for y in (0, sy) for z in (-sz / 2, sz / 2)])
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return v, f


def _shared(*parts):
    path = DATA.joinpath(*parts)
    if not DATA.is_dir():
        pytest.skip(f"{DATA} is absent (shared third-party test data)")
    return path


# ------------------------------------------------------------------------------ fixtures
def _embed(rig_or_mesh, template_rig, use_mesh=True, **kw):
    vertices, faces = rig_or_mesh
    mesh = (template_rig.vertices, template_rig.faces) if use_mesh else None
    return embed_skeleton(vertices, faces, template_rig.skeleton, template_mesh=mesh, **kw)


@pytest.fixture(scope="module")
def own_humanoid(humanoid):
    return _embed((humanoid.vertices, humanoid.faces), humanoid)


# ------------------------------------------------------------------------------ cd_j2j
def test_cd_j2j_is_the_symmetric_mean_nearest_distance_in_percent():
    truth = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    assert cd_j2j(truth, truth, 2.0) == 0.0
    # one predicted joint 0.1 off the first true joint and one exactly on the second:
    # predicted->truth mean 0.05, truth->predicted mean 0.05, average 0.05 -> 2.5% of 2.0
    pred = np.array([[0.1, 0, 0], [1.0, 0, 0]])
    assert cd_j2j(pred, truth, 2.0) == pytest.approx(2.5)
    # asymmetric sets: a single prediction at the origin against both true joints
    assert cd_j2j(np.zeros((1, 3)), truth, 1.0) == pytest.approx(100 * 0.5 * (0.0 + 0.5))
    with pytest.raises(ValueError, match="diagonal"):
        cd_j2j(pred, truth, 0.0)


# ------------------------------------------------------------------------------ the API
def test_every_template_joint_is_returned_with_stage_times(own_humanoid, humanoid):
    emb = own_humanoid
    skeleton = humanoid.skeleton
    assert isinstance(emb, Embedding)
    assert emb.positions.shape == (len(skeleton), 3)
    assert np.all(np.isfinite(emb.positions))
    assert set(emb.placed) <= set(skeleton.names)
    # the limbs come from the mesh; the ground-level root and the toes are carried
    assert {"Hips", "LeftHand", "RightFoot", "LeftForeArm"} <= set(emb.placed)
    assert "root" not in emb.placed and "LeftToeBase" not in emb.placed
    for stage in ("distance field", "search", "refinement"):
        assert emb.seconds[stage] >= 0.0
    assert np.isfinite(emb.cost)


# ------------------------------------------------------------------------------ accuracy
def test_bundled_humanoid_on_its_own_mesh(own_humanoid, humanoid):
    truth = humanoid.skeleton.bind_matrices[:, :3, 3]
    cd = cd_j2j(own_humanoid.positions, truth, _diagonal(humanoid.vertices))
    assert cd < 0.25  # measured 0.17%


@pytest.fixture(scope="module")
def own_quadruped(quadruped):
    return _embed((quadruped.vertices, quadruped.faces), quadruped)


def test_bundled_quadruped_on_its_own_mesh(own_quadruped, quadruped):
    emb = own_quadruped
    truth = quadruped.skeleton.bind_matrices[:, :3, 3]
    assert cd_j2j(emb.positions, truth, _diagonal(quadruped.vertices)) < 1.2  # measured 0.77%


def test_without_the_template_mesh_scale_and_ground_are_estimated(humanoid, quadruped):
    for rig, limit in ((humanoid, 0.2), (quadruped, 2.5)):  # measured 0.12% and 2.04%
        # (1.66% before: the head is placed 10 cm low, its carried antlers left the mesh)
        emb = _embed((rig.vertices, rig.faces), rig, use_mesh=False)
        truth = rig.skeleton.bind_matrices[:, :3, 3]
        assert cd_j2j(emb.positions, truth, _diagonal(rig.vertices)) < limit, rig.name


POSES = {
    # (rig, name): (angles, limit in %, measured)
    ("humanoid", "A-pose"): ({"LeftArm": [0, 0, -45], "RightArm": [0, 0, 45]}, 1.4),  # 0.92
    ("humanoid", "legs apart"): ({"LeftUpLeg": [0, 0, 15], "RightUpLeg": [0, 0, -15]},
                                 0.8),  # 0.52
    ("humanoid", "crouch"): ({"LeftUpLeg": [-30, 0, 0], "RightUpLeg": [-30, 0, 0],
                              "LeftLeg": [50, 0, 0], "RightLeg": [50, 0, 0],
                              "LeftFoot": [-20, 0, 0], "RightFoot": [-20, 0, 0],
                              "Spine": [10, 0, 0]}, 2.5),  # 1.66
    ("quadruped", "head down"): ({"neck_1": [25, 0, 0]}, 3.4),  # 1.76 (2.25 unturned)
    ("quadruped", "crouch"): ({"hind_thigh_L": [-15, 0, 0], "hind_thigh_R": [-15, 0, 0],
                               "hind_shin_L": [20, 0, 0], "hind_shin_R": [20, 0, 0],
                               "fore_upper_L": [15, 0, 0], "fore_upper_R": [15, 0, 0],
                               "fore_lower_L": [-20, 0, 0], "fore_lower_R": [-20, 0, 0]},
                              1.5),  # 1.00
}


@pytest.mark.parametrize("key", list(POSES), ids=[f"{a}-{b}" for a, b in POSES])
def test_posed_bundled_characters_against_their_posed_joints(key, humanoid, quadruped):
    """The rest-pose template embedded in the character skinned in another pose finds the
    posed joints (truth: the pose's joint positions)."""
    rig = humanoid if key[0] == "humanoid" else quadruped
    angles, limit = POSES[key]
    vertices, truth = _posed(rig, angles)
    emb = _embed((vertices, rig.faces), rig)
    assert cd_j2j(emb.positions, truth, _diagonal(vertices)) < limit


LEGS = {"LeftUpLeg": "leg_joint_L_1", "LeftLeg": "leg_joint_L_2", "LeftFoot": "leg_joint_L_3",
        "LeftToeBase": "leg_joint_L_5", "RightUpLeg": "leg_joint_R_1",
        "RightLeg": "leg_joint_R_2", "RightFoot": "leg_joint_R_3",
        "RightToeBase": "leg_joint_R_5"}
#: The bundled humanoid's joints -> the artists' joints (by anatomy: hip, knee, ankle, toe;
#: pelvis, lower torso, chest, neck base, skull base; shoulder, elbow, wrist). Template
#: joints with no counterpart (the clavicles, Spine1) are left out of the measure.
KHRONOS = {
    "CesiumMan.glb": dict(
        LEGS, Hips="Skeleton_torso_joint_1", Spine="Skeleton_torso_joint_2",
        Spine2="torso_joint_3", Neck="Skeleton_neck_joint_1", Head="Skeleton_neck_joint_2",
        LeftArm="Skeleton_arm_joint_L__4_", LeftForeArm="Skeleton_arm_joint_L__3_",
        LeftHand="Skeleton_arm_joint_L__2_", RightArm="Skeleton_arm_joint_R",
        RightForeArm="Skeleton_arm_joint_R__2_", RightHand="Skeleton_arm_joint_R__3_"),
    "RiggedFigure.glb": dict(
        LEGS, Hips="torso_joint_1", Spine="torso_joint_2", Spine2="torso_joint_3",
        Neck="neck_joint_1", Head="neck_joint_2", LeftArm="arm_joint_L_1",
        LeftForeArm="arm_joint_L_2", LeftHand="arm_joint_L_3", RightArm="arm_joint_R_1",
        RightForeArm="arm_joint_R_2", RightHand="arm_joint_R_3"),
}


def _khronos(name):
    rig = rigedit.load_rig(str(_shared("khronos-gltf", name)))
    rest = rig.rest_pose()
    # at the rest pose these files stand +Y up, facing +Z, left at +X: rigedit's frame
    return np.array(rig.skin(rest)), rig.faces, rig.joint_matrices(rest)[:, :3, 3], rig


@pytest.mark.parametrize("name,limit", [("CesiumMan.glb", 4.0),   # measured 2.90% (target 4%)
                                        ("RiggedFigure.glb", 4.0)])  # measured 3.03%
def test_khronos_humanoids_with_the_humanoid_template(name, limit, humanoid):
    vertices, faces, joints, rig = _khronos(name)
    table = KHRONOS[name]
    emb = _embed((vertices, faces), humanoid)
    pred = np.array([emb.positions[humanoid.skeleton.index[k]] for k in table])
    truth = np.array([joints[rig.skeleton.index[v]] for v in table.values()])
    assert cd_j2j(pred, truth, _diagonal(vertices)) < limit


def test_a_subdivided_mesh_gives_the_same_skeleton(humanoid):
    vertices, faces, joints, rig = _khronos("CesiumMan.glb")
    coarse = _embed((vertices, faces), humanoid)
    fine_v, fine_f = _subdivide(vertices, faces)
    assert len(fine_f) == 4 * len(faces)
    fine = _embed((fine_v, fine_f), humanoid)
    # the same surface, four times the triangles: the joints hardly move
    assert cd_j2j(fine.positions, coarse.positions, _diagonal(vertices)) < 0.6  # measured 0.40%
    table = KHRONOS["CesiumMan.glb"]
    pred = np.array([fine.positions[humanoid.skeleton.index[k]] for k in table])
    truth = np.array([joints[rig.skeleton.index[v]] for v in table.values()])
    assert cd_j2j(pred, truth, _diagonal(vertices)) < 4.0  # measured 2.65% (target 4%)


def test_scale_and_translation_carry_through(own_humanoid, humanoid):
    rng = np.random.default_rng(7)
    scale = float(rng.uniform(0.05, 20.0))
    shift = rng.uniform(-50, 50, size=3)
    moved = humanoid.vertices * scale + shift
    emb = embed_skeleton(moved, humanoid.faces, humanoid.skeleton,
                         template_mesh=(humanoid.vertices, humanoid.faces))
    expected = own_humanoid.positions * scale + shift
    err = np.linalg.norm(emb.positions - expected, axis=1).max() / _diagonal(moved)
    assert err < 1e-3
    assert emb.scale == pytest.approx(own_humanoid.scale * scale, rel=1e-3)


def test_small_holes_do_not_matter(humanoid):
    """Holes of 6 and 8 cm (head top, belly) in the humanoid's skin: the inside vote over
    three axes keeps the distance field, and so the skeleton."""
    v, f = humanoid.vertices, humanoid.faces
    centres = v[f].mean(axis=1)
    keep = np.ones(len(f), dtype=bool)
    for point, radius in ((v[np.argmax(v[:, 1])], 0.06), ([0.0, 0.98, 0.11], 0.08)):
        keep &= np.linalg.norm(centres - point, axis=1) > radius
    assert (~keep).sum() > 500
    emb = _embed((v, f[keep]), humanoid)
    truth = humanoid.skeleton.bind_matrices[:, :3, 3]
    assert cd_j2j(emb.positions, truth, _diagonal(v)) < 0.35  # measured 0.23%


# ------------------------------------------------------------------------------ other meshes
def _inside_fraction(points, vertices, faces):
    from rigedit.embedding.distance import distance_field
    field = distance_field(vertices, faces)
    return float(np.mean(field(points) > 0))


def test_cow_with_the_quadruped_template_has_four_legs_in_place(quadruped):
    from rigedit.io.mesh import load_mesh

    vertices, faces = load_mesh(_shared("common-3d-test-models", "cow.obj"))
    vertices = np.c_[-vertices[:, 2], vertices[:, 1], vertices[:, 0]]  # faces +X -> +Z
    emb = _embed((vertices, faces), quadruped)
    p = {n: emb.positions[j] for j, n in enumerate(quadruped.skeleton.names)}
    floor, height = vertices[:, 1].min(), np.ptp(vertices[:, 1])
    hooves = ["fore_hoof_L", "fore_hoof_R", "hind_hoof_L", "hind_hoof_R"]
    for h in hooves:
        assert p[h][1] - floor < 0.12 * height, h
    assert p["fore_hoof_L"][2] > p["hind_hoof_L"][2] + 0.3 * height
    assert p["fore_hoof_L"][0] > p["fore_hoof_R"][0] and p["hind_hoof_L"][0] > p["hind_hoof_R"][0]
    assert p["head"][2] > p["spine_3"][2] > p["pelvis"][2]
    assert p["head"][1] > p["pelvis"][1]
    placed = [j for j, n in enumerate(quadruped.skeleton.names) if n in emb.placed]
    assert _inside_fraction(emb.positions[placed], vertices, faces) > 0.95
    # the elk's antlers end in the cow's small horns: their carried tips shortened or
    # collapsed, every carried bone within a cell and a bit of the mesh (was 0.8 units out)
    assert {"antler_L_3", "antler_R_3"} <= set(emb.shortened) | set(emb.outside)
    _assert_carried_bones_inside(emb, quadruped.skeleton, vertices, faces)


def test_homer_with_the_humanoid_template_stands_in_the_body(humanoid):
    from rigedit.io.mesh import load_mesh

    vertices, faces = load_mesh(_shared("common-3d-test-models", "homer.obj"))
    emb = _embed((vertices, faces), humanoid)  # homer is +Y up, facing +Z already
    p = {n: emb.positions[j] for j, n in enumerate(humanoid.skeleton.names)}
    floor, height = vertices[:, 1].min(), np.ptp(vertices[:, 1])
    for foot in ("LeftFoot", "RightFoot"):
        assert p[foot][1] - floor < 0.12 * height
    assert p["LeftHand"][0] > p["LeftArm"][0] > p["Spine2"][0] > p["RightArm"][0] > p["RightHand"][0]
    assert p["Head"][1] > p["Spine2"][1] > p["Hips"][1] > p["LeftLeg"][1] > p["LeftFoot"][1]
    placed = [j for j, n in enumerate(humanoid.skeleton.names) if n in emb.placed]
    assert _inside_fraction(emb.positions[placed], vertices, faces) > 0.95
    # thighs where the legs meet the trunk, not in the belly (they were half-way up his
    # body, the knees at the crotch): the crotch, measured here as the lowest vertex on the
    # middle plane above the ankles, is below them, and the knees half-way down the legs
    plane = 0.5 * (p["LeftFoot"][0] + p["RightFoot"][0])
    ankle = 0.5 * (p["LeftFoot"][1] + p["RightFoot"][1])
    middle = (np.abs(vertices[:, 0] - plane) < 0.005 * height) & (vertices[:, 1] > ankle)
    crotch = vertices[middle, 1].min()
    for side in ("Left", "Right"):
        thigh, knee = p[side + "UpLeg"][1], p[side + "Leg"][1]
        assert crotch < thigh < crotch + 0.4 * (crotch - ankle)
        assert 0.35 < (knee - ankle) / (thigh - ankle) < 0.65


def test_thigh_height_from_the_crotch_keeps_the_templates_own(humanoid, quadruped):
    from rigedit.embedding.distance import distance_field
    from rigedit.embedding.legs import LEG_TOP, leg_top_heights, template_leg_top
    from rigedit.embedding.template import reduce_template

    reduced = reduce_template(humanoid.skeleton, (humanoid.vertices, humanoid.faces))
    above = template_leg_top(reduced, humanoid.vertices, humanoid.faces)
    assert 0.1 < above < 0.35  # the bundled humanoid's thighs sit above its crotch
    field = distance_field(humanoid.vertices, humanoid.faces)
    rest = reduced.rest
    # the template's joints moved off (hips 20% too high): the crotch brings them back
    moved = rest.copy()
    moved[:, 1] += 0.2 * (moved[:, 1] - moved[:, 1].min())
    heights = leg_top_heights(field, reduced, moved, rest[0, 0], above)
    names = humanoid.skeleton.names
    assert sorted(names[j] for j in heights) == ["LeftUpLeg", "RightUpLeg"]
    for j, y in heights.items():
        assert abs(y - rest[j, 1]) < 0.01 * np.ptp(rest[:, 1])
    # a quadruped's hips are not a leg radius above where its legs part: left alone
    reduced = reduce_template(quadruped.skeleton, (quadruped.vertices, quadruped.faces))
    field = distance_field(quadruped.vertices, quadruped.faces)
    assert leg_top_heights(field, reduced, reduced.rest, reduced.rest[0, 0], LEG_TOP) == {}


# ------------------------------------------------------------------------------ bad input
@pytest.mark.parametrize("shape", ["sphere", "box"])
def test_a_blob_without_limbs_is_refused_naming_what_is_missing(shape, humanoid):
    vertices, faces = _uv_sphere() if shape == "sphere" else _box(0.6, 1.8, 0.3)
    with pytest.raises(EmbeddingError, match=r"no place found for the template's .*\(\w+\)"):
        embed_skeleton(vertices, faces, humanoid.skeleton)
    assert issubclass(EmbeddingError, ValueError)


def test_malformed_arrays_are_refused(humanoid):
    with pytest.raises(EmbeddingError, match="expected"):
        embed_skeleton(np.zeros((3, 3)), np.zeros((1, 3), int), humanoid.skeleton)
    v, f = _box(1, 1, 1)
    with pytest.raises(EmbeddingError, match="face indices"):
        embed_skeleton(v, f + 100, humanoid.skeleton)


def test_progress_reports_and_an_exception_from_it_cancels(humanoid):
    seen = []

    class Cancelled(Exception):
        pass

    def progress(fraction):
        seen.append(fraction)
        if len(seen) == 3:
            raise Cancelled

    with pytest.raises(Cancelled):
        embed_skeleton(humanoid.vertices, humanoid.faces, humanoid.skeleton, progress=progress)
    assert seen == sorted(seen) and seen[0] == 0.0 and len(seen) == 3


# ------------------------------------------------------------------ carried branches inside
def _outside_distance(points, vertices, faces):
    """How far each point (N, 3) is outside the mesh (0 inside), from a dense sampling."""
    from scipy.spatial import cKDTree

    from rigedit.embedding.distance import distance_field, surface_samples

    field = distance_field(vertices, faces)
    tree = cKDTree(surface_samples(vertices, faces, field.h / 4, np.random.default_rng(1)))
    return np.where(field(points) > 0, 0.0, tree.query(points)[0]), field.h


def _assert_carried_bones_inside(emb, skeleton, vertices, faces):
    carried = [j for j, n in enumerate(skeleton.names)
               if n not in emb.placed and skeleton.parents[j] >= 0]
    t = np.linspace(0, 1, 9)[:, None, None]
    a, b = emb.positions[skeleton.parents[carried]], emb.positions[carried]
    away, h = _outside_distance((a + t * (b - a)).reshape(-1, 3), vertices, faces)
    assert away.max() < 1.5 * h, away.max() / h


def _antlerless(quadruped):
    """The bundled quadruped's faces without those skinned mostly to the antlers."""
    antler = np.array(["antler" in n for n in quadruped.skeleton.names])
    b = quadruped.binding
    top = b.indices[np.arange(len(quadruped.vertices)), np.argmax(b.weights, axis=1)]
    return quadruped.faces[~antler[top][quadruped.faces].any(axis=1)]


def test_an_antlerless_quadruped_has_its_carried_antlers_collapsed_and_reported(
        quadruped, own_quadruped):
    names = quadruped.skeleton.names
    antler = np.array(["antler" in n for n in names])
    faces = _antlerless(quadruped)
    emb = _embed((quadruped.vertices, faces), quadruped)
    assert emb.outside == [n for n in names if "antler" in n]
    assert not any("antler" in n for n in emb.placed)
    _assert_carried_bones_inside(emb, quadruped.skeleton, quadruped.vertices, faces)
    # collapsed near the head: under 30% of the template's reach, bones not of zero length
    bind = quadruped.skeleton.bind_matrices[:, :3, 3]
    head = names.index("head")
    reach = np.linalg.norm(emb.positions[antler] - emb.positions[head], axis=1)
    assert 0 < reach.min() and reach.max() < 0.3 * np.linalg.norm(bind[antler] - bind[head],
                                                                   axis=1).max()
    # its own mesh keeps the antlers where the template has them
    assert own_quadruped.outside == [] and own_quadruped.shortened == {}
    truth = quadruped.skeleton.bind_matrices[antler, :3, 3]
    err = np.linalg.norm(own_quadruped.positions[antler] - truth, axis=1)
    assert err.max() < 0.03 * _diagonal(quadruped.vertices)  # measured 4 cm of a 2.8 m diagonal


def test_autorig_stops_joints_without_geometry_deforming_and_says_so(quadruped):
    rig = rigedit.autorig((quadruped.vertices, _antlerless(quadruped)), template="quadruped",
                          weights="idw", clips=False)
    outside = rig.autorig_report.outside
    assert outside and all("antler" in n for n in outside)
    deform = dict(zip(rig.skeleton.names, rig.skeleton.deform))
    assert not any(deform[n] for n in outside)
    assert deform["head"] and deform["ear_L"] and len(rig.skeleton.names) == len(
        quadruped.skeleton.names)                          # the joints are all still there
    assert any(line.endswith(": no geometry, not deforming") and "antler_L_" in line
               for line in rig.autorig_report.lines())
    used = np.unique(rig.binding.indices[rig.binding.weights > 0])
    assert not set(used) & {rig.skeleton.names.index(n) for n in outside}


def test_a_carried_branch_is_shortened_in_proportion_until_inside():
    from rigedit.embedding.distance import distance_field
    from rigedit.embedding.inside import _STEPS, TOLERANCE, keep_inside

    vertices, faces = _subdivide(*_subdivide(*_box(2.0, 2.0, 2.0)))
    field = distance_field(vertices, faces)
    # joints 0 -> 1 placed at the middle; 2 -> 3 carried straight up through the lid (y = 2)
    positions = np.array([[0, 0.5, 0], [0, 1.0, 0], [0, 1.6, 0], [0, 3.0, 0.0]])
    parents = np.array([-1, 0, 1, 2])
    placed = np.array([True, True, False, False])
    out, cut, gone = keep_inside(field, positions, parents, placed, vertices, faces)
    assert gone == [] and list(cut) == [2]
    np.testing.assert_array_equal(out[:2], positions[:2])      # placed joints never move
    direction = (out[2:] - out[1]) / (positions[2:] - positions[1])[:, 1:2]
    np.testing.assert_allclose(direction[:, [0, 2]], 0.0, atol=1e-12)
    np.testing.assert_allclose(direction[:, 1], cut[2])        # one scale: proportions kept
    # the longest that fits: the tip within the tolerance above the lid, a step longer not
    lid = 2.0 + TOLERANCE * field(positions[1:2])[0] + field.h
    step = (_STEPS[0] - _STEPS[1]) * (positions[3, 1] - positions[1, 1])
    assert 2.0 < out[3, 1] <= lid + 0.01 < out[3, 1] + step + 0.02
    # a branch leaving sideways from a joint at the wall, with nothing there, collapses
    positions = np.array([[0, 1.0, 0], [0.9, 1.0, 0], [1.5, 1.0, 0], [2.5, 1.0, 0]])
    out, cut, gone = keep_inside(field, positions, parents, placed, vertices, faces)
    assert gone == [2, 3] and cut == {}
    assert np.all(np.abs(out[2:, 0]) < 1.0) and np.all(out[2:, 0] > 0.9)


def test_joint_runs_are_named_briefly():
    from rigedit.embedding.inside import describe_joints

    assert describe_joints(["antler_L_1", "antler_L_2", "antler_L_3", "ear_L", "tail_2",
                            "tail_4"]) == "antler_L_1..3, ear_L, tail_2, tail_4"
    assert describe_joints([]) == ""
