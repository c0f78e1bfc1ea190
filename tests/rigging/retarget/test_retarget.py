"""Retargeting: joint maps, bone directions, contacts and floor, identity, bad input."""
from __future__ import annotations

from testpaths import REPO
import json
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import rigedit
from rigedit.io.frames import change_axes
from rigedit.model import Skeleton
from rigedit.rig import Rig
from rigedit.rigging import auto_map, retarget_result
from rigedit.rigging.retarget.measure import direction_errors
from rigedit.rigging.retarget.name_map import find_slots, normalise_name
from rigedit.rigging.retarget.soles import sole_measures

DATA = REPO.parent / "shared" / "data"
CMU = DATA / "bvh-cmu" / "131_01.bvh"
WALK = DATA / "bvh-bandai" / "dataset-1_walk_normal_002.bvh"
RUN = DATA / "bvh-bandai" / "dataset-1_run_normal_001.bvh"
CESIUM = DATA / "khronos-gltf" / "CesiumMan.glb"


def _load(path):
    if not Path(path).exists():
        pytest.skip(f"shared test data missing: {path}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rigedit.load_rig(path)


def _rest_points(rig):
    sk = rig.skeleton
    return sk.forward(sk.rest_local_matrices())[:, :3, 3]


# Expected source -> humanoid pairs, read off each file's joint names and layout by hand.
EXPECTED = {
    CMU: {"Hips": "Hips", "LeftHip": "LeftUpLeg", "LeftKnee": "LeftLeg", "LeftAnkle": "LeftFoot",
          "LeftToe": "LeftToeBase", "RightKnee": "RightLeg", "LeftCollar": "LeftShoulder",
          "LeftShoulder": "LeftArm", "LeftElbow": "LeftForeArm", "LeftWrist": "LeftHand",
          "RightShoulder": "RightArm", "Chest2": "Spine2", "lowerneck": "Neck", "Head": "Head"},
    WALK: {"Hips": "Hips", "UpperLeg_L": "LeftUpLeg", "LowerLeg_R": "RightLeg",
           "Foot_L": "LeftFoot", "Toes_R": "RightToeBase", "Shoulder_L": "LeftShoulder",
           "UpperArm_L": "LeftArm", "LowerArm_R": "RightForeArm", "Hand_L": "LeftHand",
           "Chest": "Spine2", "Neck": "Neck", "Head": "Head"},
    CESIUM: {"Skeleton_torso_joint_1": "Hips", "leg_joint_L_1": "LeftUpLeg",
             "leg_joint_R_2": "RightLeg", "leg_joint_L_3": "LeftFoot",
             "leg_joint_R_5": "RightToeBase", "Skeleton_arm_joint_L__4_": "LeftArm",
             "Skeleton_arm_joint_L__3_": "LeftForeArm", "Skeleton_arm_joint_R__3_": "RightHand",
             "torso_joint_3": "Spine2", "Skeleton_neck_joint_2": "Head"},
}


@pytest.mark.parametrize("path", list(EXPECTED), ids=lambda p: p.stem)
def test_map_onto_humanoid(path, humanoid):
    src = _load(path)
    res = retarget_result(src, next(iter(src.clips)), humanoid)
    for s, t in EXPECTED[path].items():
        assert res.mapping.get(s) == t, (s, res.mapping.get(s), t)
    assert len(set(res.mapping.values())) == len(res.mapping)


def test_normalise_name():
    assert normalise_name("mixamorig:LeftForeArm") == ("L", "forearm")
    assert normalise_name("mixamorig1:RightUpLeg") == ("R", "upleg")
    assert normalise_name("thigh.L") == ("L", "thigh")
    assert normalise_name("upperarm_r") == ("R", "upperarm")
    assert normalise_name("LHipJoint") == ("L", "hip")
    assert normalise_name("rhand") == ("R", "hand")
    assert normalise_name("Spine1") == (None, "spine")


def _renamed(skeleton, rename):
    names = [rename(n) for n in skeleton.names]
    return Skeleton(names, skeleton.parents, skeleton.rest_translation, skeleton.rest_rotation,
                    skeleton.rest_scale, tails=skeleton.tails)


def test_mixamo_names_map_by_slot(humanoid):
    """Mixamo's LeftShoulder is a clavicle (CMU's is an upper arm): names with the prefix map
    onto the same slots, and a skeleton whose names say nothing still maps by structure."""
    sk = humanoid.skeleton
    for prefix in ("mixamorig:", "mixamorig1:"):
        mix = _renamed(sk, lambda n: prefix + n)
        m = auto_map(mix, _rest_points(humanoid), sk, _rest_points(humanoid))
        for n in ("Hips", "LeftShoulder", "LeftArm", "RightForeArm", "LeftUpLeg", "RightFoot",
                  "Head", "Spine1"):
            assert m[prefix + n] == n
    anon = _renamed(sk, lambda n: f"j{sk.names.index(n)}")
    m = auto_map(anon, _rest_points(humanoid), sk, _rest_points(humanoid))
    for n in ("LeftArm", "RightArm", "LeftLeg", "RightFoot", "Head", "Hips"):
        assert m[f"j{sk.names.index(n)}"] == n


COMBOS = [(CMU, "humanoid"), (CMU, CESIUM), (WALK, "humanoid"), (WALK, CESIUM),
          (RUN, "humanoid"), (RUN, CESIUM)]


@pytest.fixture(scope="module")
def results():
    cache = {}

    def get(src_path, tgt):
        key = (src_path, tgt)
        if key not in cache:
            src = _load(src_path)
            target = rigedit.load_rig(tgt) if tgt == "humanoid" else _load(tgt)
            cache[key] = retarget_result(src, "take", target)
        return cache[key]
    return get


@pytest.mark.parametrize("src,tgt", COMBOS, ids=lambda p: Path(str(p)).stem)
def test_bone_directions_agree(src, tgt, results):
    """Measured (benchmarks/bench_retarget.py): arms, spine and head 0.0 degrees on average,
    legs 1.5-4.4 (the leg IK moves thighs and shins while it holds the feet)."""
    res = results(src, tgt)
    err = direction_errors(res)
    for group in ("arms", "spine", "head"):
        assert err[group] < 0.1, (group, err)
    assert err["legs"] < 5.0, err
    raw = direction_errors(res, res.raw_mats)
    assert max(raw[g] for g in ("arms", "legs", "spine", "head")) < 0.1, raw


@pytest.mark.parametrize("src,tgt", COMBOS, ids=lambda p: Path(str(p)).stem)
def test_contacts_slip_less_and_feet_above_floor(src, tgt, results):
    """Measured on the skin (rigedit.rigging.retarget.soles, benchmarks/bench_soles.py): the soles
    never more than 1 mm below the floor, on it within 1 mm where the source's foot stands,
    slipping under 1 cm per contact. (The joints now follow the skin: a foot rolls and
    pivots about the patch it stands on, not its ankle, so an ankle's path during a contact
    is no longer held; CMU 131_01 onto CesiumMan, whose sole lies far from its ankle, moves
    it 54 mm per contact on average, 43 mm before the clean-up.)"""
    res = results(src, tgt)
    target = rigedit.load_rig(tgt) if tgt == "humanoid" else _load(tgt)
    assert res.contact.any(axis=0).all(), "every foot point touches the ground at some time"
    skin = sole_measures(res, target)
    assert skin["lowest"] > -1e-3 and abs(skin["standing"]) < 1e-3, skin
    assert skin["slips"].max() < 0.01, skin


def test_identity_reproduces_source():
    """Onto a copy of itself every joint comes back, lowered from the motion's floor (its
    feet's level over the clip) onto the target's floor (its feet at rest: the BVH rest has
    the hips at the origin). The toes too: they point 11-18 degrees off their rest during the
    motion's contacts, but the two feet are one build, so each foot points as the source's
    (the toes moved 7 mm when the target's flat foot was taken from its rest)."""
    src = _load(CMU)
    copy = _load(CMU)
    res = retarget_result(src, "take", copy, clean_feet=False)
    assert res.facing_degrees == 0 and abs(res.scale - 1) < 1e-9
    assert len(res.mapping) == len(src.skeleton)  # slots plus same-name joints
    shift = res.target_calibration.joint_floor - res.source_floor
    assert shift < -0.5  # the rest's feet are far below the motion's floor
    sk = copy.skeleton
    for t in (0.0, 1.3, 4.0, res.clip.duration):
        want = src.skeleton.forward(src.clips["take"].sample(t).local_matrices())[:, :3, 3]
        got = sk.forward(res.clip.sample(t).local_matrices())[:, :3, 3]
        err = np.abs(got - want - [0, shift, 0]).max(axis=1)
        assert err.max() < 1e-6 * copy.height()


def test_facing_backwards_source_is_turned(humanoid):
    """The humanoid's walk turned to face -Z retargets back onto the humanoid as it was
    (every joint but the ground-level ``root``: its root motion is carried by the hips)."""
    turn = Rotation.from_euler("y", 180, degrees=True).as_matrix()
    sk, clips = change_axes(humanoid.skeleton, humanoid.clips, turn)
    back = Rig(sk, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), clips=clips)
    res = retarget_result(back, "walk", humanoid, clean_feet=False)
    assert res.facing_degrees == 180
    orig = humanoid.clips["walk"]
    for t in (0.0, 0.37, 0.8):
        want = humanoid.skeleton.forward(orig.sample(t).local_matrices())[:, :3, 3]
        got = humanoid.skeleton.forward(res.clip.sample(t).local_matrices())[:, :3, 3]
        assert np.abs(got - want)[1:].max() < 1e-5


def test_a_pose_target_points_like_t_pose_source(humanoid):
    """Rest poses differ: a target whose rest lowers the arms 40 degrees and rolls the
    forearms still points every mapped bone like the T-pose source."""
    sk = humanoid.skeleton
    rest = sk.rest_rotation.copy()
    for name, sign in (("LeftArm", -1), ("RightArm", 1)):
        rest[sk.index[name]] = Rotation.from_euler("z", sign * 40, degrees=True).as_quat()
    for name in ("LeftForeArm", "RightForeArm"):
        rest[sk.index[name]] = Rotation.from_euler("x", 30, degrees=True).as_quat()
    a_sk = Skeleton(sk.names, sk.parents, sk.rest_translation, rest, sk.rest_scale,
                    tails=sk.tails)
    target = Rig(a_sk, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64))
    res = retarget_result(humanoid, "wave", target, clean_feet=False)
    err = direction_errors(res)
    assert err["arms"] < 1e-4 and err["worst"] < 1e-4, err  # degrees
    # copying the rotation relative to rest (what copying Euler angles from rest does) would
    # leave the arm 40 degrees low
    j = sk.index["RightArm"]
    src_delta = Rotation.from_quat(humanoid.clips["wave"].sample(1.0).rotation[j])
    naive = Rotation.from_quat(rest[j]) * src_delta
    new = Rotation.from_quat(res.clip.sample(1.0).rotation[j])
    assert np.degrees((naive.inv() * new).magnitude()) > 30


def _run(*argv, cwd=None):
    return subprocess.run([sys.executable, "-m", "rigedit", *map(str, argv)],
                          capture_output=True, text=True, cwd=cwd or REPO)


def test_cli_folder_and_map_round_trip(tmp_path):
    _load(WALK)
    out = tmp_path / "char"
    saved = tmp_path / "map.json"
    p = _run("retarget", WALK, "--to", "humanoid", "--name", "bandai_walk", "-o", out,
             "--save-map", saved)
    assert p.returncode == 0, p.stderr
    assert "UpperArm_L -> LeftArm" in p.stdout
    rig = rigedit.load_rig(out)
    assert {"bandai_walk", "walk", "idle", "wave"} <= set(rig.clips)
    mapping = json.loads(saved.read_text())
    mapping.pop("Hand_L")  # an edited map: the left hand is left out and keeps its rest
    saved.write_text(json.dumps(mapping))
    p = _run("retarget", WALK, "--to", "humanoid", "--map", saved, "-o", tmp_path / "c.json")
    assert p.returncode == 0, p.stderr
    clip = rigedit.io.clip_json.load_clip(tmp_path / "c.json", rig.skeleton)
    assert ("LeftHand", "rotation") not in clip.tracks
    assert ("RightHand", "rotation") in clip.tracks
    a = clip.sample(0.5)
    b = rig.clips["bandai_walk"].sample(0.5)
    assert np.allclose(a.translation, b.translation)  # legs and hips as before


BVH_NO_LEGS = """HIERARCHY
ROOT Hips
{
  OFFSET 0 90 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0 20 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT LeftArm
    {
      OFFSET 20 20 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT LeftHand
      {
        OFFSET 30 0 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        End Site
        {
          OFFSET 10 0 0
        }
      }
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0333333
0 90 0 0 0 0 0 0 0 0 0 0 0 0 0
0 90 0 0 0 0 0 0 0 0 0 0 0 0 0
"""


def test_bad_input_one_line(tmp_path):
    bvh = tmp_path / "stick.bvh"
    bvh.write_text(BVH_NO_LEGS)
    for argv, words in (
            (("retarget", bvh, "--to", "humanoid", "-o", tmp_path / "a.json"),
             (str(bvh), "expected legs", "found none")),
            (("retarget", "humanoid", "--clip", "walk", "--to", bvh, "-o", tmp_path / "b.json"),
             (str(bvh), "expected legs", "found none")),
            # a quadruped onto a humanoid: no structure in common and no shared names
            (("retarget", "quadruped", "--clip", "walk", "--to", "humanoid", "-o",
              tmp_path / "c.json"), ("quadruped", "no joint maps onto the target's hips",
                                     "--map")),
            (("retarget", "humanoid", "--to", "humanoid", "-o", tmp_path / "d.json"),
             ("humanoid", "--clip"))):
        p = _run(*argv)
        assert p.returncode == 2, p.stderr
        lines = [ln for ln in p.stderr.splitlines() if not ln.startswith("rigedit: warning")]
        assert len(lines) == 1 and lines[0].startswith("rigedit: error:"), p.stderr
        assert all(w in lines[0] for w in words), lines[0]
    bad_map = tmp_path / "m.json"
    bad_map.write_text(json.dumps({"NoSuchJoint": "Hips"}))
    p = _run("retarget", "humanoid", "--clip", "walk", "--to", "humanoid", "--map", bad_map,
             "-o", tmp_path / "e.json")
    assert p.returncode == 2 and str(bad_map) in p.stderr and "NoSuchJoint" in p.stderr


def test_find_slots_needs_legs(humanoid):
    sk = humanoid.skeleton
    keep = [j for j, n in enumerate(sk.names) if "Leg" not in n and "Foot" not in n
            and "Toe" not in n]
    pts = _rest_points(humanoid)
    names = [sk.names[j] for j in keep]
    parents = [keep.index(sk.parents[j]) if sk.parents[j] >= 0 else -1 for j in keep]
    legless = Skeleton(names, parents, sk.rest_translation[keep])
    with pytest.raises(ValueError, match="two legs"):
        find_slots(legless, pts[keep], "legless.json")


def test_spine_bend_shared_with_unmapped_joint(humanoid):
    """Bandai's spine has one joint between hips and chest, the humanoid's two: the unmapped
    one takes part of the bend (it is not left at rest), and the mapped bones still point
    like the source's."""
    res = retarget_result(_load(WALK), "take", humanoid)
    assert "Spine" not in res.mapping.values() and "Spine1" in res.mapping.values()
    j = humanoid.skeleton.index["Spine"]
    track = res.clip.tracks[("Spine", "rotation")]
    rest = Rotation.from_quat(humanoid.skeleton.rest_rotation[j])
    angles = (rest.inv() * Rotation.from_quat(track.values)).magnitude()
    assert np.degrees(angles.max()) > 1.0
    assert direction_errors(res)["spine"] < 0.1


def test_clip_plays_the_result_and_root_carries_travel(humanoid):
    """The clip's forward kinematics give the result's joints; the humanoid's ground-level
    root carries the horizontal travel (as in the bundled walk), the hips the rest."""
    res = retarget_result(_load(WALK), "take", humanoid)
    sk = humanoid.skeleton
    for f in (0, len(res.times) // 2, len(res.times) - 1):
        got = sk.forward(res.clip.sample(res.times[f]).local_matrices())[:, :3, 3]
        assert np.abs(got - res.mats[f, :, :3, 3])[1:].max() < 1e-9  # root: below
    root = res.clip.tracks[("root", "translation")].values
    assert np.allclose(root[:, 1], 0.0)
    assert np.linalg.norm(root[-1] - root[0]) > 0.5  # about one stride of the Bandai walk


def test_api_retarget_returns_a_clip_of_the_target(humanoid):
    clip = rigedit.retarget(_load(RUN), "take", humanoid, name="bandai_run")
    assert isinstance(clip, rigedit.Clip) and clip.name == "bandai_run"
    assert clip.skeleton is humanoid.skeleton
    assert abs(clip.duration - _load(RUN).clips["take"].duration) < 1e-9
    moving = [j for (j, ch) in clip.tracks if ch == "rotation"]
    assert {"LeftUpLeg", "RightLeg", "LeftArm", "Spine2", "Head"} <= set(moving)


def _with_joints(skeleton, extra, rest_rotation=None):
    """``skeleton`` with joints ``[(name, parent name, offset)]`` appended (identity rest
    rotations), and optionally other rest rotations for its own joints."""
    names = list(skeleton.names) + [e[0] for e in extra]
    index = {n: i for i, n in enumerate(names)}
    parents = list(skeleton.parents) + [index[e[1]] for e in extra]
    trans = np.r_[skeleton.rest_translation, [e[2] for e in extra]]
    rot = np.r_[skeleton.rest_rotation if rest_rotation is None else rest_rotation,
                np.tile([0.0, 0.0, 0.0, 1.0], (len(extra), 1))]
    scale = np.r_[skeleton.rest_scale, np.ones((len(extra), 3))]
    return Skeleton(names, parents, trans, rot, scale)


def test_unmapped_target_joints_keep_the_calibration_pose_not_a_lying_rest(humanoid):
    """A target whose rest lies down (as Bandai's and iClone's do) is calibrated on its
    clip's first frame; an unmapped joint (a face joint between the head and a mapped eye)
    must keep its relation to its parent in that frame: kept at rest, it turned the head's
    bone (head to eye) 85 degrees off on the iClone rig."""
    sk = humanoid.skeleton
    src_sk = _with_joints(sk, [("LeftEye", "Head", (0.03, 0.07, 0.10))])
    src = Rig(src_sk, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64),
              clips={"walk": _rebound(humanoid.clips["walk"], src_sk)})
    lying = sk.rest_rotation.copy()
    lying[sk.index["root"]] = Rotation.from_euler("x", 90, degrees=True).as_quat()
    tgt_sk = _with_joints(sk, [("Face", "Head", (0.0, 0.05, 0.05)),
                               ("LeftEye", "Face", (0.03, 0.02, 0.05))], lying)
    from rigedit.animation.clip import Clip, Track
    stand = {("root", "rotation"): Track("rotation", [0.0], [[0.0, 0.0, 0.0, 1.0]]),
             ("Face", "rotation"): Track("rotation", [0.0], [Rotation.from_euler(
                 "x", 30, degrees=True).as_quat()])}
    tgt = Rig(tgt_sk, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64),
              clips={"stand": Clip("stand", tgt_sk, stand, duration=0.0)})
    res = retarget_result(src, "walk", tgt, clean_feet=False)
    assert res.target_calibration.source == "frame 0 of stand"
    assert res.mapping["LeftEye"] == "LeftEye" and "Face" not in res.mapping.values()
    raw = direction_errors(res, res.raw_mats)
    assert max(raw[g] for g in ("arms", "legs", "spine", "head")) < 0.01, raw


def _rebound(clip, skeleton):
    from rigedit.animation.clip import Clip

    return Clip(clip.name, skeleton, dict(clip.tracks), duration=clip.duration, loop=clip.loop)
