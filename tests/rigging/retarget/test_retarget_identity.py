"""Identity: a character's clip retargeted onto the same character changes nothing.

Every character in the shared data that has clips, the Mixamo one first, the bundled ones,
and each BVH skeleton onto itself; and synthetic cases of what broke the identity before
(a Mixamo-style centimetre skeleton under a 0.01 scale).
"""
from __future__ import annotations

from testpaths import REPO
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import rigedit
from rigedit.animation.clip import Clip, Track
from rigedit.model import Skeleton
from rigedit.rig import Rig
from rigedit.rigging import retarget_result
from rigedit.rigging.retarget.calibrate import model_stack
from rigedit.rigging.retarget.measure import direction_errors, lowest_foot

DATA = REPO.parent / "shared" / "data"
XBOT = DATA / "threejs-characters" / "Xbot.glb"


def _load(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rigedit.load_rig(path)


def _positions(rig, clip, times):
    return model_stack(rig.skeleton, clip, times)[..., :3, 3]


def _centimetre_copy(rig):
    """The rig with its ground-level ``root`` scaled by 0.01 and everything below it in
    centimetres (as a Mixamo glTF's Armature node or hips do): the same figure in model
    space, with the same clips."""
    sk = rig.skeleton
    root = sk.index["root"]
    scale = sk.rest_scale.copy()
    scale[root] *= 0.01
    trans = sk.rest_translation.copy()
    below = np.arange(len(sk)) != root  # every bone below the scaled root is in cm
    trans[below] *= 100.0
    cm = Skeleton(sk.names, sk.parents, trans, sk.rest_rotation, scale, tails=sk.tails)
    clips = {}
    for name, clip in rig.clips.items():
        tracks = {}
        for (joint, kind), tr in clip.tracks.items():
            values = tr.values
            if kind == "translation" and below[sk.index[joint]]:
                values = values * 100.0
            tracks[(joint, kind)] = Track(kind, tr.times, values, tr.interpolation)
        clips[name] = Clip(name, cm, tracks, duration=clip.duration, loop=clip.loop)
    return Rig(cm, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), clips=clips)


def test_centimetre_skeleton_under_a_scaled_root_keeps_its_bone_lengths(humanoid):
    """The bones below a 0.01 scale are in centimetres: the retarget must build each joint's
    model matrix with the scale it inherits (it used its own, 1, so every bone came out 100x
    long and the leg IK turned the legs by 40-170 degrees on Xbot)."""
    cm = _centimetre_copy(humanoid)
    times = np.linspace(0.0, cm.clips["walk"].duration, 7)
    want = _positions(humanoid, humanoid.clips["walk"], times)
    assert np.abs(_positions(cm, cm.clips["walk"], times) - want).max() < 1e-9
    res = retarget_result(cm, "walk", cm, clean_feet=False)
    got = _positions(cm, res.clip, times)
    hips = cm.skeleton.index["Hips"]
    body = [j for j in range(len(cm.skeleton)) if j != cm.skeleton.index["root"]]
    # every joint where it was (the floor is the motion's: a constant vertical shift)
    shift = got[:, hips] - want[:, hips]
    assert np.abs(shift[:, [0, 2]]).max() < 1e-9
    err = np.abs(got[:, body] - want[:, body] - shift[:, None]).max()
    assert err < 1e-6
    res = retarget_result(cm, "walk", cm)
    assert direction_errors(res)["arms"] < 1e-3
    assert np.abs(res.mats[..., :3, :3]).max() < 0.011  # the model scale is kept: 0.01


def test_xbot_walk_onto_itself():
    """The Mixamo character's own walk onto itself: every bone points where it did (before
    the fix the legs were 88 degrees off on average, up to 174) and every joint is where it
    was."""
    xbot = _load(XBOT)
    res = retarget_result(xbot, "walk", xbot)
    err = direction_errors(res)
    assert max(err[g] for g in ("arms", "legs", "spine", "head")) < 0.5, err
    raw = retarget_result(xbot, "walk", xbot, clean_feet=False)
    want = _positions(xbot, xbot.clips["walk"], raw.times)
    got = _positions(xbot, raw.clip, raw.times)
    assert np.abs(got - want).max() < 0.01 * np.ptp(want[..., 1])


def _ancestors(sk, j):
    out = []
    while j >= 0:
        out.append(j)
        j = sk.parents[j]
    return out


def _shared(*parts):
    return DATA.joinpath(*parts)


#: Every character with clips in the shared data and the bundled ones, with its clips; the
#: BVH skeletons onto themselves. RiggedSimple has no legs, and RobotExpressive's and the
#: horse's feet are IK targets under the root: they retarget by names (:mod:`.bare`).
CHARACTERS = [(XBOT, c) for c in ("walk", "run", "idle", "agree", "headShake", "sad_pose",
                                  "sneak_pose")] + [
    pytest.param((_shared("khronos-gltf", "CesiumMan.glb"), None), marks=pytest.mark.xfail(
        reason="the floor: the motion's (5th percentile of its lowest foot joint) is not the "
               "rest's, so the retarget raises the figure 14.5 mm (retarget.py's floor rule)",
        strict=False)),
    (_shared("khronos-gltf", "RiggedFigure.glb"), None),
    (_shared("khronos-gltf", "RiggedSimple.glb"), None),
    (_shared("threejs-characters", "RobotExpressive.glb"), "Walking"),
    (_shared("threejs-characters", "RobotExpressive.glb"), "Wave"),
    (_shared("quaternius-farm-animals", "Horse.gltf"), "Walk"),
    ("humanoid", "walk"), ("humanoid", "wave"), ("humanoid", "idle"),
    ("quadruped", "walk"), ("quadruped", "run"),
    (_shared("bvh-cmu", "131_01.bvh"), None),
    (_shared("bvh-bandai", "dataset-1_walk_normal_002.bvh"), None),
    (_shared("bvh-library", "bandai-2", "dataset-2_walk_active_001.bvh"), None),
    (_shared("bvh-library", "cmu-iclone", "005_01.bvh"), None),
    (_shared("bvh-library", "cmu-iclone", "002_01.bvh"), None),
]


def _ids(case):
    path, clip = case
    return f"{Path(str(path)).stem}-{clip}" if clip else Path(str(path)).stem


_RIGS = {}


def _rig(path):
    if path not in _RIGS:
        _RIGS[path] = _load(path)
    return _RIGS[path]


def _groups(res):
    return [g for g in res.target_calibration.groups]


@pytest.mark.parametrize("case", CHARACTERS, ids=_ids)
def test_identity_before_the_foot_clean_up(case):
    """Every mapped bone, feet included, points where it did (0.5 degrees; measured 0.0001
    at most) and every joint is where it was, up to the floor's vertical shift (the motion's
    floor, a low percentile of its feet, onto the rest's: measured 2.9 mm on Xbot's walk;
    the BVH rests do not stand on the motion's floor)."""
    path, clip = case
    rig = _rig(path)
    clip = clip or next(iter(rig.clips))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the bare retarget says it had no legs
        res = retarget_result(rig, clip, rig, clean_feet=False)
    assert res.facing_degrees == 0 and abs(res.scale - 1) < 1e-9
    err = direction_errors(res)
    assert max(v for g, v in err.items() if np.isfinite(v)) < 0.5, err
    sk = rig.skeleton
    want = _positions(rig, rig.clips[clip], res.times)
    got = _positions(rig, res.clip, res.times)
    # animated translations of joints other than the hips and roots are not transferred
    # (glTF exports key them on every joint; Xbot's sneak_pose moves its thighs' offsets
    # 1-2 cm): each joint may be off by what its ancestors' offsets move, and no more
    hips = res.target_calibration.hips
    moved = np.zeros(len(sk))
    for (joint, channel), tr in rig.clips[clip].tracks.items():
        j = sk.index[joint]
        if channel == "translation" and j != hips and sk.parents[j] >= 0:
            scale = np.linalg.norm(model_stack(rig.skeleton, rig.clips[clip], res.times[:1])
                                   [0, sk.parents[j], :3, 0])
            moved[j] = np.linalg.norm(tr.values - sk.rest_translation[j], axis=1).max() * scale
    slack = np.array([sum(moved[a] for a in _ancestors(sk, j)) for j in range(len(sk))])
    # a root above the hips carries the travel its own way
    carried = [j for j in range(len(sk)) if sk.parents[j] < 0 and j != hips]
    body = np.setdiff1d(np.arange(len(sk)), carried)
    delta = got[:, body] - want[:, body]
    shift = np.median(delta[:, [list(body).index(hips)], 1])
    tol = 1e-4 * np.ptp(want[..., 1]) + 1e-6 + 2 * slack[body]
    assert (np.abs(delta[..., [0, 2]]).max(axis=(0, 2)) < tol).all()
    assert (np.abs(delta[..., 1] - shift).max(axis=0) < tol).all()
    if res.source_calibration.source == "rest" and res.target_calibration.joint_floor > -0.05:
        assert abs(shift) < 0.01  # a standing rest: the feet stay on their floor


@pytest.mark.parametrize("case", [c.values[0] if hasattr(c, "marks") else c
                                  for c in CHARACTERS if "bvh" not in str(c)], ids=_ids)
def test_identity_after_the_foot_clean_up_keeps_the_upper_body(case):
    """With the clean-up, arms, spine, head and fingers still point where they did."""
    path, clip = case
    rig = _rig(path)
    clip = clip or next(iter(rig.clips))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        err = direction_errors(retarget_result(rig, clip, rig))
    upper = [g for g in ("arms", "spine", "head", "fingers", "tail", "bones") if g in err]
    assert max(err[g] for g in upper if np.isfinite(err[g])) < 0.5, err


def test_another_motion_onto_a_centimetre_skeleton_stands_on_its_floor(humanoid):
    """The Bandai-style failure on Mixamo characters (bones 35-49 degrees off, feet 0.6-0.9 m
    above the floor) was the same missing scale: the humanoid's walk onto its centimetre
    copy points every bone as the source's and keeps the feet on the floor."""
    cm = _centimetre_copy(humanoid)
    res = retarget_result(humanoid, "walk", cm)
    err = direction_errors(res)
    assert max(err[g] for g in ("arms", "spine", "head")) < 0.01, err
    assert err["legs"] < 5.0, err
    raw = direction_errors(res, res.raw_mats)
    assert max(raw[g] for g in ("arms", "legs", "spine", "head")) < 0.01, raw
    assert abs(lowest_foot(res)) < 0.01  # metres, whatever the skeleton's units


def _ik_rig(size=1.0):
    """A game rig whose foot is an IK target under the root (as RobotExpressive's and the
    horse's): root -> body -> thigh -> shin (ending at the knee), root -> foot, and a clip
    that moves the body and the foot by translation and bends the leg."""
    from rigedit.animation.clip import Clip as _Clip

    names = ["Root", "Body", "UpperLeg.L", "LowerLeg.L", "Foot.L"]
    parents = [-1, 0, 1, 2, 0]
    trans = np.array([[0, 0, 0], [0, 1.0, 0], [0.1, -0.1, 0], [0, -0.45, 0],
                      [0.1, 0.05, 0]]) * size
    sk = Skeleton(names, parents, trans)
    times = np.linspace(0.0, 1.0, 11)
    wave = np.sin(2 * np.pi * times)
    bend = Rotation.from_euler("x", 30 * wave[:, None], degrees=True).as_quat()
    knee = Rotation.from_euler("x", -40 * wave.clip(0)[:, None], degrees=True).as_quat()
    tracks = {("Body", "translation"): Track("translation", times,
                                             trans[1] + np.c_[0 * wave, 0.05 * wave, times]
                                             * size),
              ("Foot.L", "translation"): Track("translation", times,
                                               trans[4] + np.c_[0 * wave, 0.1 * wave.clip(0),
                                                                times] * size),
              ("UpperLeg.L", "rotation"): Track("rotation", times, bend),
              ("LowerLeg.L", "rotation"): Track("rotation", times, knee)}
    rig = Rig(sk, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64))
    rig.clips["walk"] = _Clip("walk", sk, tracks, duration=1.0)
    return rig


def test_ik_rig_with_feet_under_the_root_retargets_onto_itself_and_a_bigger_copy():
    """Before: "expected legs (chains of three or more joints ...), found none". The rig's
    own clip comes back exactly, the IK foot's translation included; onto a copy twice the
    size the translations double and the rotations are the same; the retarget says it went
    without legs."""
    rig = _ik_rig()
    with pytest.warns(UserWarning, match="without a floor, facing or foot clean-up"):
        res = retarget_result(rig, "walk", rig)
    times = res.times
    want = _positions(rig, rig.clips["walk"], times)
    assert np.abs(_positions(rig, res.clip, times) - want).max() < 1e-9
    big = _ik_rig(size=2.0)
    with pytest.warns(UserWarning):
        res = retarget_result(rig, "walk", big)
    assert abs(res.scale - 2.0) < 1e-9
    assert np.abs(_positions(big, res.clip, times) - 2 * want).max() < 1e-9
    # a legged target is no rig of its family: the error stands
    with pytest.raises(ValueError, match="expected legs"):
        retarget_result(rig, "walk", _load_humanoid())


def _load_humanoid():
    return rigedit.load_rig("humanoid")


def test_cli_retargets_an_ik_rig_by_names_with_one_warning(tmp_path):
    import subprocess
    import sys

    folder = tmp_path / "ik"
    _ik_rig().save(folder)
    p = subprocess.run([sys.executable, "-m", "rigedit", "retarget", str(folder), "--to",
                        str(folder), "--strict", "-o", str(tmp_path / "c.json")],
                       capture_output=True, text=True, cwd=REPO)
    assert p.returncode == 0, p.stderr
    warn = [ln for ln in p.stderr.splitlines() if ln.startswith("rigedit: warning:")]
    assert len(warn) == 1 and "retargeted by joint names (5 of 5 joints)" in warn[0], p.stderr
    assert "Traceback" not in p.stderr and (tmp_path / "c.json").exists()
