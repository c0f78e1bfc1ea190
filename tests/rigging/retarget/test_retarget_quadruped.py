"""Retargeting beyond humanoids: the bundled quadruped's clips onto quadrupeds of other
proportions, rest poses and joint names (a JSON map), legs found by structure, bad input."""
from __future__ import annotations

from testpaths import REPO
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import rigedit
from rigedit.io.frames import change_axes
from rigedit.rig import Rig
from rigedit.rigging import retarget_result
from rigedit.rigging.retarget.calibrate import calibrate
from rigedit.rigging.retarget.limbs import LegCalibration
from rigedit.rigging.retarget.measure import (direction_errors, foot_slip, lowest_foot,
                                     source_foot_points, target_foot_points)

from quadruped_variants import VARIANTS, fore_variant, renamed, variant

@pytest.fixture(scope="module")
def quad():
    return rigedit.load_rig("quadruped")


def _positions(skeleton, clip, t):
    return skeleton.forward(clip.sample(t).local_matrices())[:, :3, 3]


def test_legs_found_by_structure(quad):
    sk = quad.skeleton
    cal = calibrate(sk, [], "quadruped", LegCalibration)
    names = lambda js: [sk.names[j] for j in js]  # noqa: E731
    assert sorted(names(cal.contacts)) == ["fore_hoof_L", "fore_hoof_R", "hind_hoof_L",
                                           "hind_hoof_R"]
    assert sk.names[cal.hips] == "pelvis" and sk.names[cal.chest] == "spine_3"
    fore = next(leg for leg in cal.legs if sk.names[leg.contact] == "fore_hoof_L")
    assert names(fore.chain) == ["scapula_L", "fore_upper_L", "fore_lower_L", "fore_cannon_L",
                                 "fore_hoof_L"]
    assert np.allclose(cal.forward, [0, 0, 1]) and np.allclose(cal.left, [1, 0, 0])
    groups = {n: cal.group(j) for j, n in enumerate(sk.names)}
    assert groups["tail_3"] == "tail" and groups["spine_2"] == "spine"
    assert groups["antler_L_2"] == "head" and groups["hind_cannon_R"] == "legs"
    assert groups["root"] is None
    # a humanoid's legs by the same rule: two, ending at the toes, hanging from the hips
    hum = rigedit.load_rig("humanoid").skeleton
    hcal = calibrate(hum, [], "humanoid", LegCalibration)
    assert sorted(hum.names[j] for j in hcal.contacts) == ["LeftToeBase", "RightToeBase"]
    assert hum.names[hcal.hips] == "Hips" and hcal.chest is None


@pytest.mark.parametrize("clip", ["walk", "run", "idle", "head_nod"])
def test_identity_reproduces_the_clip(quad, clip):
    """Onto itself (the identity map is found from the names) every joint comes back: exactly
    without the foot clean-up, within 1 cm with it (it holds the source's own slip, 0-4 mm
    per contact on average; measured 6.1 mm at most, at a fore cannon)."""
    raw = retarget_result(quad, clip, quad, clean_feet=False)
    res = retarget_result(quad, clip, quad)
    assert raw.mapping == {n: n for n in quad.skeleton.names}
    assert raw.facing_degrees == 0 and abs(raw.scale - 1) < 1e-12
    src = quad.clips[clip]
    for t in np.linspace(0, src.duration, 7):
        want = _positions(quad.skeleton, src, t)
        assert np.abs(_positions(quad.skeleton, raw.clip, t) - want).max() < 1e-6
        assert np.abs(_positions(quad.skeleton, res.clip, t) - want).max() < 1e-2


@pytest.fixture(scope="module")
def results(quad):
    cache = {}

    def get(vname, clip):
        if (vname, clip) not in cache:
            cache[vname, clip] = retarget_result(quad, clip, variant(quad.skeleton,
                                                                    **VARIANTS[vname]))
        return cache[vname, clip]
    return get


CASES = [(v, c) for v in VARIANTS for c in ("walk", "run")]


@pytest.mark.parametrize("vname,clip", CASES)
def test_bones_point_like_the_source(results, vname, clip):
    """Before the clean-up every mapped bone points exactly as its source bone (whatever the
    target's proportions and rest pose); after it the tail still does, the legs within a
    degree on average (measured 0.01-0.5), and the spine, neck and head within the body's
    pitch: none where the fore and hind legs keep the source's ratio (a uniform scale),
    1.4 degrees at most measured on the others."""
    res = results(vname, clip)
    raw = direction_errors(res, res.raw_mats)
    assert max(raw[g] for g in ("legs", "spine", "head", "tail")) < 1e-6, raw
    err = direction_errors(res)
    assert err["tail"] < 1e-6 and err["legs"] < 1.0, err
    uniform = "scale" in VARIANTS[vname] and "legs" not in VARIANTS[vname]
    assert max(err["spine"], err["head"]) < (1e-6 if uniform else 2.0), err


@pytest.mark.parametrize("fore,sign", [(0.8, -1), (1.25, 1)])
def test_body_pitches_for_shorter_or_longer_fore_legs(quad, fore, sign):
    """Fore legs 20% shorter (25% longer) than the bundled ones, hind legs as they are, the
    rest's spine turned so all four hooves stand on the floor (a hyena, a giraffe): the body
    turns about the hips, front down (up), instead of dropping and bending the legs; the
    hooves still hold and stay on the floor."""
    target = fore_variant(quad.skeleton, fore)
    assert len(calibrate(target.skeleton, [], "variant", LegCalibration).legs) == 4
    res = retarget_result(quad, "walk", target)
    hips = res.target_calibration.hips
    # the hips do not drop (measured 0.0 mm for both)
    assert np.abs(res.mats[:, hips, 1, 3] - res.raw_mats[:, hips, 1, 3]).max() < 0.005
    err = direction_errors(res)
    assert err["legs"] < 1.0 and err["tail"] < 1e-6, err
    assert 8.0 < err["spine"] < 25.0, err  # measured 13.3 and 17.5 degrees
    sk = target.skeleton
    spine = res.mats[:, sk.index["spine_3"], :3, 3] - res.mats[:, hips, :3, 3]
    raw_spine = res.raw_mats[:, sk.index["spine_3"], :3, 3] - res.raw_mats[:, hips, :3, 3]
    assert np.all(sign * (spine[:, 1] - raw_spine[:, 1]) > 0.05)
    assert foot_slip(target_foot_points(res), res.contact).max() < 1e-6
    assert lowest_foot(res) > -1e-6


@pytest.mark.parametrize("vname,clip", CASES)
def test_feet_hold_and_stay_above_the_floor(results, vname, clip):
    res = results(vname, clip)
    assert res.contact.any(axis=0).all(), "each of the four hooves touches at some time"
    before = foot_slip(target_foot_points(res, res.raw_mats), res.contact)
    after = foot_slip(target_foot_points(res), res.contact)
    assert after.max() < 1e-6, after  # each contact held still (measured 1e-12)
    src = foot_slip(source_foot_points(res), res.contact) * res.scale
    if abs(res.scale - 1.3) < 1e-9:  # longer legs: the raw feet slide (1.9x the source)
        assert before.mean() > 1.5 * src.mean()
    assert lowest_foot(res) > -1e-6
    hoof_tips = res.target_calibration.foot_points(res.mats)[..., 1].min(axis=1)
    # on the floor while a hoof stands: the lowest point is the floor in most frames
    assert np.median(hoof_tips) - res.target_calibration.floor < 1e-3


def test_root_travel_scales_with_the_hind_legs(quad, results):
    res = results("small (x0.6), bent rest legs", "walk")
    assert abs(res.scale - 0.6) < 1e-9  # bones x0.6: the bent rest does not change it
    stride = np.ptp(quad.clips["walk"].tracks[("root", "translation")].values[:, 2])
    root = res.clip.tracks[("root", "translation")].values
    assert abs(np.ptp(root[:, 2]) - 0.6 * stride) < 0.01 * stride
    assert np.allclose(root[:, 1], 0.0)


def test_bent_rest_legs_are_not_copied_as_angles(quad, results):
    """The variant's rest turns the upper legs 20 degrees: copying the source's local
    rotations would keep that bend; the retarget points the legs as the source does."""
    res = results("small (x0.6), bent rest legs", "walk")
    sk = res.clip.skeleton
    j = sk.index["fore_upper_L"]
    t = 0.4
    naive = Rotation.from_quat(sk.rest_rotation[j]) * Rotation.from_quat(
        quad.clips["walk"].sample(t).rotation[j])
    got = Rotation.from_quat(res.clip.sample(t).rotation[j])
    assert np.degrees((naive.inv() * got).magnitude()) > 15


@pytest.mark.parametrize("vname", list(VARIANTS))
def test_other_names_map_by_the_trees_shape_or_a_map(quad, results, vname):
    """Unrelated names (``Q_ForeHoof.l``): the map found from the trees' shape pairs every
    joint below the ground-level root as the names say, and gives the same motion as equal
    names; so does a given map."""
    target = variant(quad.skeleton, **VARIANTS[vname], rename=renamed)
    same = results(vname, "walk")
    res = retarget_result(quad, "walk", target)
    assert res.mapping == {n: renamed(n) for n in quad.skeleton.names if n != "root"}
    assert np.abs(res.mats - same.mats).max() < 1e-9
    mapping = {n: renamed(n) for n in quad.skeleton.names}
    res = retarget_result(quad, "walk", target, map=mapping)
    assert np.abs(res.mats - same.mats).max() < 1e-9


def test_tree_map_pairs_a_shorter_neck_and_no_antlers(quad):
    """Another build of the same animal: two neck joints instead of three, no antlers, no
    tail; the neck's ends pair, the missing joints are left out, the legs pair by side."""
    from rigedit.model import Skeleton
    from rigedit.rigging.retarget.tree_map import tree_map

    sk = quad.skeleton
    drop = {"neck_2", "tail_1", "tail_2", "tail_3", "tail_4"} | {
        n for n in sk.names if n.startswith("antler")}
    keep = [j for j, n in enumerate(sk.names) if n not in drop]
    pts = sk.bind_matrices[:, :3, 3]
    parents, names = [], []
    for j in keep:
        p = sk.parents[j]
        while p >= 0 and sk.names[p] in drop:
            p = sk.parents[p]
        parents.append(keep.index(p) if p >= 0 else -1)
        names.append("B" + sk.names[j].upper())
    trans = np.array([pts[j] - (pts[keep[parents[i]]] if parents[i] >= 0 else 0)
                      for i, j in enumerate(keep)])
    other = Skeleton(names, parents, trans, tails=sk.tails[keep])
    src = calibrate(sk, [], "quadruped", LegCalibration)
    tgt = calibrate(other, [], "other", LegCalibration)
    m = tree_map(src, tgt)
    for n in ("pelvis", "spine_2", "spine_3", "neck_1", "head", "jaw", "ear_L", "ear_R",
              "scapula_L", "fore_cannon_R", "hind_thigh_L", "hind_hoof_R"):
        assert m[n] == "B" + n.upper(), (n, m.get(n))
    assert "neck_3" not in m or m["neck_3"] == "BNECK_3"
    assert not set(m) & drop


def _run(*argv):
    return subprocess.run([sys.executable, "-m", "rigedit", *map(str, argv)],
                          capture_output=True, text=True, cwd=REPO)


def _one_error(p, *words):
    assert p.returncode == 2, p.stderr
    lines = [ln for ln in p.stderr.splitlines() if not ln.startswith("rigedit: warning")]
    assert len(lines) == 1 and lines[0].startswith("rigedit: error:"), p.stderr
    assert all(w in lines[0] for w in words), lines[0]
    assert "Traceback" not in p.stderr


def test_cli_json_map_onto_renamed_quadruped_and_bad_input(quad, tmp_path):
    """The CLI with a JSON map onto a quadruped of other names; then the three messages of
    issue 11 section 4: a BVH whose joints map to nothing, a target without legs, a map
    naming unknown joints (one line naming the file, exit 2)."""
    target = variant(quad.skeleton, **VARIANTS["big (x1.5), short legs"], rename=renamed)
    folder = tmp_path / "other"
    target.save(folder)
    mapping = tmp_path / "map.json"
    mapping.write_text(json.dumps({n: renamed(n) for n in quad.skeleton.names}))
    out = tmp_path / "walk.json"
    p = _run("retarget", "quadruped", "--clip", "walk", "--to", folder, "--map", mapping,
             "-o", out)
    assert p.returncode == 0, p.stderr
    assert "fore_hoof_L -> Q_ForeHoof.l" in p.stdout
    assert "legs: target 4 (feet Q_ForeHoof.l, Q_ForeHoof.r, Q_HindHoof.l, Q_HindHoof.r), " \
        "source 4; hips Q_Pelvis" in p.stdout
    clip = rigedit.io.clip_json.load_clip(out, rigedit.load_rig(folder).skeleton)
    direct = retarget_result(quad, "walk", variant(quad.skeleton,
                                                   **VARIANTS["big (x1.5), short legs"]))
    assert np.allclose(clip.sample(0.3).rotation, direct.clip.sample(0.3).rotation, atol=1e-6)
    # that clip as a BVH of other joint names maps back onto the quadruped by shape
    moving = Rig(target.skeleton, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64),
                 clips={"walk": clip})
    bvh = tmp_path / "other_walk.bvh"
    moving.save(bvh)
    p = _run("retarget", bvh, "--to", "quadruped", "-o", tmp_path / "back.json")
    assert p.returncode == 0, p.stderr
    assert "Q_HindShin.r -> hind_shin_R" in p.stdout
    # a humanoid BVH of other joint names: two legs against four, nothing maps
    hum = rigedit.load_rig("humanoid")
    hsk = hum.skeleton
    bip = type(hsk)([f"Bip_{n}" for n in hsk.names], hsk.parents, hsk.rest_translation,
                    tails=hsk.tails)
    walker = Rig(bip, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64))
    walker.clips["walk"] = rigedit.retarget(hum, "walk", walker)
    bvh = tmp_path / "human_walk.bvh"
    walker.save(bvh)
    _one_error(_run("retarget", bvh, "--to", "quadruped", "-o", tmp_path / "a.json"),
               str(bvh), "none of its", "joints maps onto", "legs differ", "--map")
    # a target without legs: the quadruped cut at the shoulders and hips
    sk = quad.skeleton
    keep = [j for j, n in enumerate(sk.names) if not n.startswith(("fore_", "hind_"))]
    legless = Rig(type(sk)([sk.names[j] for j in keep],
                           [keep.index(sk.parents[j]) if sk.parents[j] >= 0 else -1
                            for j in keep], sk.rest_translation[keep],
                           tails=sk.tails[keep]), np.zeros((0, 3)),
                  np.zeros((0, 3), dtype=np.int64))
    stumps = tmp_path / "stumps"
    legless.save(stumps)
    _one_error(_run("retarget", "quadruped", "--clip", "walk", "--to", stumps, "-o",
                    tmp_path / "b.json"), str(stumps), "expected legs", "found none")
    # a map naming a joint the target does not have
    bad = tmp_path / "bad_map.json"
    bad.write_text(json.dumps({"pelvis": "Q_Pelvis", "fore_hoof_L": "Q_NoSuchHoof"}))
    _one_error(_run("retarget", "quadruped", "--clip", "walk", "--to", folder, "--map", bad,
                    "-o", tmp_path / "c.json"), str(bad), "Q_NoSuchHoof")


def test_api_map_naming_unknown_joints(quad):
    target = variant(quad.skeleton, scale=0.8)
    with pytest.raises(ValueError, match="'hoof_X'"):
        retarget_result(quad, "walk", target, map={"pelvis": "pelvis", "hoof_X": "tail_1"})
    with pytest.raises(ValueError, match="hips"):
        retarget_result(quad, "walk", target, map={"tail_1": "tail_1"})


def test_facing_backwards_quadruped_is_turned(quad):
    """The quadruped's walk turned to face -Z comes back onto the quadruped as it was."""
    turn = Rotation.from_euler("y", 180, degrees=True).as_matrix()
    sk, clips = change_axes(quad.skeleton, quad.clips, turn)
    back = Rig(sk, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), clips=clips)
    res = retarget_result(back, "walk", quad, clean_feet=False)
    assert res.facing_degrees == 180
    for t in (0.0, 0.37, 0.8):
        want = _positions(quad.skeleton, quad.clips["walk"], t)
        assert np.abs(_positions(quad.skeleton, res.clip, t) - want).max() < 1e-6


@pytest.mark.parametrize("template", ["quadruped", "humanoid"])
def test_template_clips_onto_a_character_of_its_names(template):
    """What auto-rigging does: every clip of a template onto a character with the template's
    joint names and hierarchy, other proportions (legs x1.2, all x0.9) and no clips."""
    rig = rigedit.load_rig(template)
    sk = rig.skeleton
    trans = sk.rest_translation * 0.9
    legs = [j for j, n in enumerate(sk.names)
            if any(w in n for w in ("hind_", "fore_lower", "fore_cannon", "fore_hoof",
                                    "Leg", "Foot", "ToeBase"))]
    trans[legs] *= 1.2
    new_sk = type(sk)(sk.names, sk.parents, trans, sk.rest_rotation, deform=sk.deform)
    new = Rig(new_sk, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64))
    for name, clip in rig.clips.items():
        res = retarget_result(rig, name, new)
        assert set(res.mapping.items()) >= {(n, n) for n in sk.names if n != "root"}
        err = direction_errors(res)
        groups = [g for g in res.target_calibration.groups if g not in ("legs", "feet")]
        # the quadruped's body pitches where its fore legs grew less than its hind legs
        # (measured up to 3.4 degrees); a humanoid's body does not
        assert max(err[g] for g in groups) < (5.0 if template == "quadruped" else 1e-3), \
            (name, err)
        assert err["legs"] < 3.0, (name, err)
        assert lowest_foot(res) > -1e-6
        assert res.clip.duration == clip.duration and res.clip.skeleton is new_sk


def test_blender_style_names_map_by_normalised_names(quad, results):
    """``HindThigh.L`` for ``hind_thigh_L``: equal normalised names (side and words) pair
    without a map."""
    def blender(name):
        side = ""
        if name.endswith(("_L", "_R")):
            name, side = name[:-2], "." + name[-1]
        return "".join(w.capitalize() for w in name.split("_")) + side
    target = variant(quad.skeleton, **VARIANTS["long legs, short neck"], rename=blender)
    res = retarget_result(quad, "walk", target)
    assert res.mapping == {n: blender(n) for n in quad.skeleton.names}
    assert np.abs(res.mats - results("long legs, short neck", "walk").mats).max() < 1e-9


def test_jittered_joints_as_an_embedding_places_them(quad):
    """An auto-rigged character's joints are where the embedding put them, not on a clean
    grid: every joint moved by up to a few centimetres, no tails. The legs are still found,
    the hooves held and kept above the floor, the tail points as the source's and the body
    within its pitch."""
    sk = quad.skeleton
    rng = np.random.default_rng(7)
    trans = sk.rest_translation + np.clip(rng.normal(0, 0.015, sk.rest_translation.shape),
                                          -0.04, 0.04)
    trans[0] = 0.0
    pts = type(sk)(sk.names, sk.parents, trans, deform=sk.deform).bind_matrices[1:, 1, 3]
    trans[1, 1] -= pts.min()  # hooves on the floor again
    target = Rig(type(sk)(sk.names, sk.parents, trans, deform=sk.deform), np.zeros((0, 3)),
                 np.zeros((0, 3), dtype=np.int64))
    for clip in ("walk", "run"):
        res = retarget_result(quad, clip, target)
        assert len(res.target_calibration.legs) == 4
        assert res.contact.any(axis=0).all()
        assert foot_slip(target_foot_points(res), res.contact).max() < 1e-6
        assert lowest_foot(res) > -1e-6
        err = direction_errors(res)
        assert err["tail"] < 1e-6, err
        assert max(err["spine"], err["head"]) < 3.0, err  # the pitch: measured 2.0 degrees
        assert err["legs"] < 3.0, err


def test_bird_toes_make_one_leg():
    """Three toes branching at a low foot: one leg from the thigh to the lowest toe, the
    whole foot (foot joint and toes) moving with the ankle."""
    from rigedit.model import Skeleton
    from rigedit.rigging.retarget.limbs import find_legs

    names = ["hips", "neck", "head"]
    parents = [-1, 0, 1]
    trans = [[0, 1.0, 0], [0, 0.3, 0.2], [0, 0.3, 0.1]]
    for side, x in (("L", 0.1), ("R", -0.1)):
        base = len(names)
        names += [f"thigh_{side}", f"shin_{side}", f"foot_{side}", f"toe_a_{side}",
                  f"toe_b_{side}", f"toe_c_{side}"]
        parents += [0, base, base + 1, base + 2, base + 2, base + 2]
        trans += [[x, -0.1, 0], [0, -0.4, 0.05], [0, -0.4, -0.05], [0, -0.1, 0.12],
                  [0.03, -0.1, 0.1], [0, -0.1, -0.08]]
    sk = Skeleton(names, parents, np.array(trans, dtype=float))
    legs, hips, chest = find_legs(sk, sk.bind_matrices)
    assert len(legs) == 2 and sk.names[hips] == "hips" and chest is None
    left = legs[0]
    assert [sk.names[j] for j in left.chain] == ["thigh_L", "shin_L", "foot_L", "toe_a_L"]
    assert (sk.names[left.upper], sk.names[left.knee], sk.names[left.ankle]) == \
        ("thigh_L", "shin_L", "foot_L")
    assert sorted(sk.names[j] for j in left.foot) == ["foot_L", "toe_a_L", "toe_b_L",
                                                      "toe_c_L"]
