"""Identity: a character's clip retargeted onto the same character changes nothing.

Every character in the shared data that has clips, the Mixamo one first, the bundled ones,
and each BVH skeleton onto itself; and synthetic cases of what broke the identity before
(a Mixamo-style centimetre skeleton under a 0.01 scale).
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import rigedit
from rigedit.animation.clip import Clip, Track
from rigedit.model import Skeleton
from rigedit.rig import Rig
from rigedit.rigging import retarget_result
from rigedit.rigging.calibrate import model_stack
from rigedit.rigging.measure import direction_errors

REPO = Path(__file__).resolve().parents[1]
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
