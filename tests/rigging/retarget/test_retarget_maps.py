"""Joint maps that come from the skeletons: an iClone / Character Creator rig (prefixed
names, a pelvis under the hips, twist and share bones, fingers), a carrier root metres away,
fingers onto fingers, the same skeleton mapping the same way in every file, and the warning
(an error with --strict) for a map that leaves a limb, the spine or the head unmapped."""
from __future__ import annotations

from testpaths import REPO
import json
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import rigedit
from rigedit.model import Skeleton
from rigedit.rig import Rig
from rigedit.rigging import auto_map, retarget_result
from rigedit.rigging.retarget.calibrate import calibrate
from rigedit.rigging.retarget.measure import direction_errors
from rigedit.rigging.retarget.name_map import find_slots, finger_pairs, unmapped_parts

DATA = REPO.parent / "shared" / "data"
ICLONE = DATA / "bvh-library" / "cmu-iclone"
XBOT = DATA / "threejs-characters" / "Xbot.glb"


def _load(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rigedit.load_rig(path)


def _from_points(joints):
    """A skeleton from ``[(name, parent name or None, model position)]`` in parent-first
    order, every rest rotation the identity."""
    names = [j[0] for j in joints]
    parents = [names.index(p) if p is not None else -1 for _, p, _ in joints]
    pos = np.array([j[2] for j in joints], dtype=np.float64)
    trans = np.array([pos[i] - (pos[p] if p >= 0 else 0.0) for i, p in enumerate(parents)])
    return Skeleton(names, parents, trans)


def _humanoid_points(humanoid):
    sk = humanoid.skeleton
    return dict(zip(sk.names, sk.forward(sk.rest_local_matrices())[:, :3, 3]))


FINGERS = ("Thumb", "Index", "Mid", "Ring", "Pinky")


def _iclone_like(humanoid, carrier=(0.0, 0.0, 0.0)):
    """The bundled humanoid's rest rebuilt as a Character Creator rig: ``CC_Base_`` names, a
    carrier ``RL_BoneRoot`` at ``carrier``, a pelvis under the hips carrying the thighs,
    twist and share bones at the thigh, calf, upper arm and forearm joints (listed before the
    real child, so a chain that takes the first child goes astray), three-joint fingers."""
    p = _humanoid_points(humanoid)
    j = [("RL_BoneRoot", None, carrier), ("CC_Base_Hip", "RL_BoneRoot", p["Hips"]),
         ("CC_Base_Pelvis", "CC_Base_Hip", p["Hips"] - [0, 0.02, 0])]
    for side, s in (("L", "Left"), ("R", "Right")):
        thigh, calf, foot = p[f"{s}UpLeg"], p[f"{s}Leg"], p[f"{s}Foot"]
        j += [(f"CC_Base_{side}_Thigh", "CC_Base_Pelvis", thigh),
              (f"CC_Base_{side}_ThighTwist01", f"CC_Base_{side}_Thigh", thigh),
              (f"CC_Base_{side}_ThighTwist02", f"CC_Base_{side}_ThighTwist01",
               (thigh + calf) / 2),
              (f"CC_Base_{side}_Calf", f"CC_Base_{side}_Thigh", calf),
              (f"CC_Base_{side}_KneeShareBone", f"CC_Base_{side}_Calf", calf),
              (f"CC_Base_{side}_CalfTwist01", f"CC_Base_{side}_Calf", calf),
              (f"CC_Base_{side}_CalfTwist02", f"CC_Base_{side}_CalfTwist01",
               (calf + foot) / 2),
              (f"CC_Base_{side}_Foot", f"CC_Base_{side}_Calf", foot),
              (f"CC_Base_{side}_ToeBaseShareBone", f"CC_Base_{side}_Foot", p[f"{s}ToeBase"]),
              (f"CC_Base_{side}_ToeBase", f"CC_Base_{side}_Foot", p[f"{s}ToeBase"]),
              (f"CC_Base_{side}_BigToe1", f"CC_Base_{side}_ToeBase",
               p[f"{s}ToeBase"] + [0, 0, 0.04])]
    j += [("CC_Base_Waist", "CC_Base_Hip", p["Spine"]),
          ("CC_Base_Spine01", "CC_Base_Waist", p["Spine1"]),
          ("CC_Base_Spine02", "CC_Base_Spine01", p["Spine2"]),
          ("CC_Base_NeckTwist01", "CC_Base_Spine02", p["Neck"]),
          ("CC_Base_Head", "CC_Base_NeckTwist01", p["Head"]),
          ("CC_Base_FacialBone", "CC_Base_Head", p["Head"] + [0, 0.05, 0.05])]
    for side, s in (("L", "Left"), ("R", "Right")):
        arm, fore, hand = p[f"{s}Arm"], p[f"{s}ForeArm"], p[f"{s}Hand"]
        out = (hand - fore) / np.linalg.norm(hand - fore)
        j += [(f"CC_Base_{side}_Clavicle", "CC_Base_Spine02", p[f"{s}Shoulder"]),
              (f"CC_Base_{side}_Upperarm", f"CC_Base_{side}_Clavicle", arm),
              (f"CC_Base_{side}_UpperarmTwist01", f"CC_Base_{side}_Upperarm", arm),
              (f"CC_Base_{side}_UpperarmTwist02", f"CC_Base_{side}_UpperarmTwist01",
               (arm + fore) / 2),
              (f"CC_Base_{side}_Forearm", f"CC_Base_{side}_Upperarm", fore),
              (f"CC_Base_{side}_ElbowShareBone", f"CC_Base_{side}_Forearm", fore),
              (f"CC_Base_{side}_Hand", f"CC_Base_{side}_Forearm", hand)]
        for k, f in enumerate(FINGERS):
            base = hand + out * 0.04 + [0, 0, 0.02 * (2 - k)]
            parent = f"CC_Base_{side}_Hand"
            for n in (1, 2, 3):
                name = f"CC_Base_{side}_{f}{n}"
                j.append((name, parent, base + out * 0.025 * (n - 1)))
                parent = name
    return _from_points(j)


def _mixamo_with_fingers(humanoid):
    """The bundled humanoid with ``mixamorig:`` names and Mixamo's four-joint fingers."""
    p = _humanoid_points(humanoid)
    sk = humanoid.skeleton
    j = [(f"mixamorig:{n}", None if sk.parents[i] < 0 else f"mixamorig:{sk.names[sk.parents[i]]}",
          p[n]) for i, n in enumerate(sk.names)]
    for s in ("Left", "Right"):
        fore, hand = p[f"{s}ForeArm"], p[f"{s}Hand"]
        out = (hand - fore) / np.linalg.norm(hand - fore)
        for k, f in enumerate(("Thumb", "Index", "Middle", "Ring", "Pinky")):
            base = hand + out * 0.05 + [0, 0, 0.02 * (2 - k)]
            parent = f"mixamorig:{s}Hand"
            for n in (1, 2, 3, 4):
                name = f"mixamorig:{s}Hand{f}{n}"
                j.append((name, parent, base + out * 0.02 * (n - 1)))
                parent = name
    return _from_points(j)


def _points(sk):
    return sk.forward(sk.rest_local_matrices())[:, :3, 3]


def test_iclone_rig_finds_its_slots_through_pelvis_twists_and_prefix(humanoid):
    """Before: "expected a humanoid with two legs ..." (the legs hang from the pelvis, not
    from the joint the spine leaves) and the neck ran to the face (``CC_Base_Head`` was no
    "head")."""
    sk = _iclone_like(humanoid)
    slots, chains, _ = find_slots(sk, _points(sk), "iclone")
    got = {k: sk.names[v] for k, v in slots.items()}
    want = {"hips": "CC_Base_Hip", "chest": "CC_Base_Spine02", "head": "CC_Base_Head",
            "thigh_L": "CC_Base_L_Thigh", "shin_L": "CC_Base_L_Calf",
            "foot_L": "CC_Base_L_Foot", "toe_L": "CC_Base_L_ToeBase",
            "thigh_R": "CC_Base_R_Thigh", "shin_R": "CC_Base_R_Calf",
            "foot_R": "CC_Base_R_Foot", "toe_R": "CC_Base_R_ToeBase",
            "clavicle_L": "CC_Base_L_Clavicle", "upper_arm_L": "CC_Base_L_Upperarm",
            "forearm_L": "CC_Base_L_Forearm", "hand_L": "CC_Base_L_Hand",
            "upper_arm_R": "CC_Base_R_Upperarm", "forearm_R": "CC_Base_R_Forearm",
            "hand_R": "CC_Base_R_Hand"}
    for k, v in want.items():
        assert got.get(k) == v, (k, got.get(k), v)


def test_carrier_root_metres_away_does_not_shrink_the_figure(humanoid):
    """A carrier root 5.4 m from the figure made every size test relative to 5.4 m (the legs
    were no longer "going down" by a quarter of it): no humanoid found."""
    for sk, hips, arm in ((_iclone_like(humanoid, carrier=(0.0, 0.0, -5.4)), "CC_Base_Hip",
                           "CC_Base_L_Upperarm"),
                          (_carried(humanoid.skeleton, (0.0, 0.0, -5.4)), "Hips", "LeftArm")):
        slots, _, _ = find_slots(sk, _points(sk), "far")
        assert sk.names[slots["hips"]] == hips
        assert sk.names[slots["upper_arm_L"]] == arm


def _carried(sk, carrier):
    """``sk`` below one more root, a carrier at ``carrier`` (model positions kept)."""
    p = _points(sk)
    return _from_points([("Carrier", None, carrier)] + [
        (n, "Carrier" if sk.parents[i] < 0 else sk.names[sk.parents[i]], p[i])
        for i, n in enumerate(sk.names)])


def test_fingers_map_when_both_sides_have_them(humanoid):
    """iClone's Index1..3 onto Mixamo's Index1..4: 1-3 pair and Mixamo's tip stays out;
    Mid onto Middle."""
    src, tgt = _iclone_like(humanoid), _mixamo_with_fingers(humanoid)
    m = auto_map(src, _points(src), tgt, _points(tgt))
    for side, s in (("L", "Left"), ("R", "Right")):
        for a, b in (("Index", "Index"), ("Mid", "Middle"), ("Thumb", "Thumb"),
                     ("Pinky", "Pinky")):
            for n in (1, 2, 3):
                assert m[f"CC_Base_{side}_{a}{n}"] == f"mixamorig:{s}Hand{b}{n}"
        assert f"mixamorig:{s}HandIndex4" not in m.values()
    # no fingers on one side: nothing to pair, nothing wrong
    sk = humanoid.skeleton
    assert finger_pairs(src, src.index["CC_Base_L_Hand"], sk, sk.index["LeftHand"]) == []


def test_unmapped_limbs_are_listed(humanoid):
    cal = calibrate(humanoid.skeleton, [], "humanoid")
    sk = humanoid.skeleton
    everything = range(len(sk))
    assert unmapped_parts(cal, everything) == []
    missing = unmapped_parts(cal, [j for j in everything
                                   if sk.names[j] not in ("LeftForeArm", "Head")])
    assert missing == ["left arm (LeftForeArm)", "head (Head)"]


@pytest.mark.parametrize("name", ["005_01", "007_01"])
def test_iclone_clips_map_fully_onto_xbot(name):
    """The 100-joint CC rig (007_01 has RL_BoneRoot above) onto the Mixamo character: every
    limb, the spine, the head and the fingers (5 x 3 per hand), bones pointing as their
    source bones before the foot clean-up."""
    src, xbot = _load(ICLONE / f"{name}.bvh"), _load(XBOT)
    res = retarget_result(src, "take", xbot)
    tsk = xbot.skeleton
    assert unmapped_parts(res.target_calibration,
                          [tsk.index[t] for t in res.mapping.values()]) == []
    fingers = [t for t in res.mapping.values() if "Hand" in t and t[-1].isdigit()]
    assert len(fingers) == 30
    raw = direction_errors(res, res.raw_mats)
    assert max(raw[g] for g in ("arms", "legs", "spine", "head", "fingers")) < 0.01, raw


def test_same_skeleton_maps_the_same_way_in_every_file():
    """Four files on the CC rig, two with a carrier RL_BoneRoot above: one map onto Xbot."""
    xbot = _load(XBOT)
    maps = []
    for f in sorted(ICLONE.glob("*.bvh")):
        src = _load(f)
        m = retarget_result(src, "take", xbot, clean_feet=False).mapping
        maps.append({s: t for s, t in m.items() if s != "RL_BoneRoot"})
    assert len(maps) == 4 and all(m == maps[0] for m in maps[1:])


def _run(*argv):
    return subprocess.run([sys.executable, "-m", "rigedit", *map(str, argv)],
                          capture_output=True, text=True, cwd=REPO)


def test_cli_warns_of_unmapped_limbs_and_strict_fails(humanoid, tmp_path):
    """A motion whose left arm ends at the shoulder onto the humanoid (no humanoid to the
    slot finder: the pair is calibrated by its legs and mapped by names): a warning listing
    the left arm's joints; with --strict exit 2 and nothing written; an edited map that
    leaves out the head: the head."""
    sk = humanoid.skeleton
    drop = set(sk.subtree(sk.index["LeftArm"]).tolist())
    keep = [j for j in range(len(sk)) if j not in drop]
    p = _points(sk)
    stub = _from_points([(sk.names[j], None if sk.parents[j] < 0 else sk.names[sk.parents[j]],
                          p[j]) for j in keep])
    rig = Rig(stub, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64))
    rig.clips["still"] = rigedit.animation.clip.Clip("still", stub, {}, duration=1.0)
    folder = tmp_path / "onearm"
    rig.save(folder)
    out = tmp_path / "a.json"
    res = _run("retarget", folder, "--to", "humanoid", "-o", out)
    assert res.returncode == 0, res.stderr
    warn = [ln for ln in res.stderr.splitlines() if "unmapped" in ln]
    assert len(warn) == 1 and "left arm (LeftArm, LeftForeArm, LeftHand)" in warn[0], \
        res.stderr
    assert "right arm" not in warn[0]
    out2 = tmp_path / "b.json"
    res = _run("retarget", folder, "--to", "humanoid", "--strict", "-o", out2)
    assert res.returncode == 2
    lines = [ln for ln in res.stderr.splitlines() if ln.startswith("rigedit: error:")]
    assert len(lines) == 1 and "left arm" in lines[0] and "--strict" in lines[0]
    assert not out2.exists()
    saved = tmp_path / "map.json"
    assert _run("retarget", "humanoid", "--clip", "walk", "--to", "humanoid", "--save-map",
                saved, "-o", tmp_path / "c.json").returncode == 0
    mapping = json.loads(saved.read_text())
    del mapping["Head"]
    saved.write_text(json.dumps(mapping))
    res = _run("retarget", "humanoid", "--clip", "walk", "--to", "humanoid", "--map", saved,
               "-o", tmp_path / "d.json")
    assert res.returncode == 0 and "unmapped (they keep their rest pose): head (Head)" in \
        res.stderr, res.stderr


#: The bundled humanoid's joints as other rigs name them (Unreal's mannequin, 3ds Max's
#: biped, MotionBuilder's HumanIK), each with twist leaves beside the real children.
NAMINGS = {
    "unreal": {"root": "root", "Hips": "pelvis", "Spine": "spine_01", "Spine1": "spine_02",
               "Spine2": "spine_03", "Neck": "neck_01", "Head": "head",
               "LeftShoulder": "clavicle_l", "LeftArm": "upperarm_l",
               "LeftForeArm": "lowerarm_l", "LeftHand": "hand_l", "LeftUpLeg": "thigh_l",
               "LeftLeg": "calf_l", "LeftFoot": "foot_l", "LeftToeBase": "ball_l"},
    "biped": {"root": "Bip01", "Hips": "Bip01 Pelvis", "Spine": "Bip01 Spine",
              "Spine1": "Bip01 Spine1", "Spine2": "Bip01 Spine2", "Neck": "Bip01 Neck",
              "Head": "Bip01 Head", "LeftShoulder": "Bip01 L Clavicle",
              "LeftArm": "Bip01 L UpperArm", "LeftForeArm": "Bip01 L Forearm",
              "LeftHand": "Bip01 L Hand", "LeftUpLeg": "Bip01 L Thigh",
              "LeftLeg": "Bip01 L Calf", "LeftFoot": "Bip01 L Foot",
              "LeftToeBase": "Bip01 L Toe0"},
    "humanik": {n: f"Character1_{n}" for n in ("Hips", "Spine", "Spine1", "Spine2", "Neck",
                                               "Head", "LeftShoulder", "LeftArm",
                                               "LeftForeArm", "LeftHand", "LeftUpLeg",
                                               "LeftLeg", "LeftFoot", "LeftToeBase")}
    | {"root": "Character1_Reference"},
}


def _renamed_with_twists(humanoid, naming):
    sk = humanoid.skeleton
    p = _points(sk)

    def rename(n):
        if n in naming:
            return naming[n]
        left = n.replace("Right", "Left")
        out = naming[left]
        return (out.replace("_l", "_r") if out.endswith("_l") else
                out.replace(" L ", " R ").replace("Left", "Right"))
    joints = []
    for i, n in enumerate(sk.names):
        parent = None if sk.parents[i] < 0 else rename(sk.names[sk.parents[i]])
        joints.append((rename(n), parent, p[i]))
        if n.endswith(("UpLeg", "Arm")) and "Fore" not in n:
            # a twist leaf at the limb joint, its first child (before the real one)
            joints.append((rename(n) + "_twist", rename(n), p[i]))
    return _from_points(joints)


@pytest.mark.parametrize("naming", list(NAMINGS))
def test_other_rigs_names_map_onto_the_humanoid(humanoid, naming):
    """Unreal, 3ds Max biped and HumanIK names with twist leaves under the thighs and upper
    arms: every slot lands on the humanoid's joint of the same role."""
    names = NAMINGS[naming]
    src = _renamed_with_twists(humanoid, names)
    sk = humanoid.skeleton
    m = auto_map(src, _points(src), sk, _points(sk))
    for orig in ("Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftArm", "LeftForeArm",
                 "LeftHand", "Head", "Spine2"):
        assert m.get(names[orig]) == orig, (naming, orig, m.get(names[orig]))
    assert m.get(names["LeftLeg"].replace("_l", "_r").replace(" L ", " R ")
                 .replace("Left", "Right")) == "RightLeg"
