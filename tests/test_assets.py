"""The bundled characters (assets/quadruped, assets/humanoid): mesh, skeleton, weights, clips.

numpy only: no Qt, no VTK.
"""
from __future__ import annotations

import numpy as np
import pytest

import rigedit
from rigedit.model.skinning import dense_weights


@pytest.fixture(scope="module", params=["quadruped", "humanoid"])
def rig(request):
    return rigedit.load_rig(request.param)


@pytest.fixture(scope="module")
def quad():
    return rigedit.load_rig("quadruped")


@pytest.fixture(scope="module")
def human():
    return rigedit.load_rig("humanoid")


def edge_counts(faces):
    """Undirected edge multiplicities and directed edge multiplicities."""
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    _, und = np.unique(np.sort(e, axis=1), axis=0, return_counts=True)
    _, directed = np.unique(e, axis=0, return_counts=True)
    return und, directed


def test_edge_counts_detect_holes_and_flips():
    tet = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    und, d = edge_counts(tet)
    assert np.all(und == 2) and np.all(d == 1)
    und, _ = edge_counts(tet[:3])
    assert np.any(und == 1)
    flipped = tet.copy()
    flipped[0] = flipped[0, ::-1]
    _, d = edge_counts(flipped)
    assert np.any(d > 1)


def test_mesh_closed_manifold_oriented(rig):
    und, directed = edge_counts(rig.faces)
    assert np.all(und == 2), "every edge must be shared by exactly two faces"
    assert np.all(directed == 1), "faces must be consistently oriented"
    used = np.zeros(len(rig.vertices), bool)
    used[rig.faces.ravel()] = True
    assert used.all()
    # Outward orientation: positive enclosed volume; one closed piece: Euler characteristic 2.
    a, b, c = (rig.vertices[rig.faces[:, i]] for i in range(3))
    assert np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6 > 0
    assert len(rig.vertices) - len(und) + len(rig.faces) == 2


def test_mesh_size_and_placement(rig):
    assert 15_000 <= len(rig.vertices) <= 50_000
    lo, hi = rig.bounds()
    assert abs(lo[1]) < 1e-3, "stands on y = 0"
    assert rig.up == "y"
    if rig.name == "quadruped":
        assert 1.7 <= hi[2] - lo[2] <= 2.4          # about 2 m long, along z
        head = rig.skeleton.bind_matrices[rig.skeleton.joint_index("head"), 1, 3]
        assert 1.5 <= head <= 2.0
        nose = rig.skeleton.tails[rig.skeleton.joint_index("head")]
        assert nose[2] > 0.9, "faces +Z"
    else:
        assert 1.70 <= hi[1] - lo[1] <= 1.80
        assert hi[0] - lo[0] > 1.5, "T-pose: arms along X"
        sk = rig.skeleton
        hand = sk.bind_matrices[sk.joint_index("LeftHand"), :3, 3]
        arm = sk.bind_matrices[sk.joint_index("LeftArm"), :3, 3]
        assert hand[0] > arm[0] + 0.4 and abs(hand[1] - arm[1]) < 0.02, "left arm along +X"
        toe = sk.tails[sk.joint_index("LeftToeBase")]
        assert toe[2] > 0.1, "faces +Z"


QUAD_NAMES = (["root", "pelvis", "spine_1", "spine_2", "spine_3", "neck_1", "neck_2", "neck_3",
               "head", "jaw", "ear_L", "ear_R", "tail_1", "tail_2", "tail_3", "tail_4"]
              + [f"{p}_{s}" for s in "LR" for p in
                 ("hind_thigh", "hind_shin", "hind_cannon", "hind_hoof",
                  "fore_upper", "fore_lower", "fore_cannon", "fore_hoof")])
HUMAN_NAMES = ["Hips", "Spine", "Spine1", "Spine2", "Neck", "Head"] + [
    f"{s}{n}" for s in ("Left", "Right") for n in
    ("UpLeg", "Leg", "Foot", "ToeBase", "Shoulder", "Arm", "ForeArm", "Hand")]


def test_skeletons(quad, human):
    assert 30 <= len(quad.skeleton) <= 60
    assert set(QUAD_NAMES) <= set(quad.skeleton.names)
    assert not quad.skeleton.deform[quad.skeleton.joint_index("root")]
    assert quad.skeleton.bind_matrices[0, 1, 3] == 0.0
    assert 20 <= len(human.skeleton) <= 30
    assert set(HUMAN_NAMES) <= set(human.skeleton.names)
    for rig in (quad, human):
        sk = rig.skeleton
        assert np.allclose(sk.rest_rotation, [0, 0, 0, 1]), "axis-aligned joint frames"
        for j in np.flatnonzero(sk.deform):   # leaves carry a tail for the weights
            if len(sk.children(j)) == 0:
                assert np.all(np.isfinite(sk.tails[j])), sk.names[j]


def test_weights_normalised(rig):
    b = rig.binding
    assert b.indices.shape[1] <= 4
    assert np.allclose(b.weights.sum(axis=1), 1.0)
    assert np.all(b.weights >= 0)
    dense = dense_weights(b.indices, b.weights, len(rig.skeleton))
    assert np.all(dense[:, ~rig.skeleton.deform] == 0), "non-deforming joints take no weight"


def _regions(rig):
    """Joint -> exclusive region (legs, arms, ears, tail, antlers) for the rig."""
    reg = {}
    for n in rig.skeleton.names:
        if rig.name == "quadruped":
            for pre in ("hind_", "fore_", "ear_", "antler_"):
                if n.startswith(pre):
                    reg[n] = pre + n[-1] if pre != "antler_" else n[:8]
            if n.startswith("scapula_"):
                reg[n] = "fore_" + n[-1]
            if n.startswith("tail_"):
                reg[n] = "tail"
        else:
            for s in ("Left", "Right"):
                for part, names in (("leg", ("UpLeg", "Leg", "Foot", "ToeBase")),
                                    ("arm", ("Shoulder", "Arm", "ForeArm", "Hand"))):
                    if n.startswith(s) and n[len(s):] in names:
                        reg[n] = s + part
    return reg


def test_regions_do_not_mix(rig):
    reg = _regions(rig)
    names = rig.skeleton.names
    assert len(set(reg.values())) >= (8 if rig.name == "quadruped" else 4)
    of = np.array([reg.get(n, "") for n in names])
    b = rig.binding
    main = of[b.indices[np.arange(len(b.indices)), np.argmax(b.weights, axis=1)]]
    vr = of[b.indices]
    # A vertex owned by a limb (or ear, tail) has no weight on another limb's joints.
    for r in set(reg.values()):
        rows = main == r
        assert rows.sum() > 50, r
        other = (vr[rows] != r) & (vr[rows] != "") & (b.weights[rows] > 0)
        assert not other.any(), f"{r} vertices weighted to {set(vr[rows][other])}"


def test_every_clip_loops(rig):
    expected = {"quadruped": {"idle", "head_nod", "walk", "run"},
                "humanoid": {"idle", "wave", "walk"}}[rig.name]
    assert expected <= set(rig.clips)
    moving = 0
    for clip in rig.clips.values():
        assert clip.loop and clip.duration > 0
        a, b = clip.sample(0.0), clip.sample(clip.duration)
        # Root motion: the root's translation advances; everything else comes back.
        a.translation[0] = b.translation[0]
        assert a.allclose(b, atol=1e-6), clip.name
        mid = clip.sample(clip.duration * 0.37)
        moving += not mid.allclose(a, atol=1e-3)
    assert moving == len(rig.clips), "every clip moves something"


@pytest.mark.parametrize("clip", ["walk", "run"])
def test_root_motion_forward(quad, clip):
    c = quad.clips[clip]
    z0 = c.sample(0.0).translation[0]
    z1 = c.sample(c.duration).translation[0]
    assert z1[2] - z0[2] > 0.5 and abs(z1[0] - z0[0]) < 1e-9 and abs(z1[1] - z0[1]) < 1e-9


def foot_slide(rig, clip_name, foot_joints, fps=120, contact=0.012, touch=0.003):
    """How far planted feet slide in a clip.

    A foot is the set of vertices mainly weighted to its joint; it is in contact while its
    lowest skinned vertex is within ``contact`` metres of the ground (the rest mesh's lowest
    point). Two measures per contact interval, worst over all intervals and feet:

    - ``lowest``: horizontal drift of the lowest vertex from where it was at touchdown,
      counted while that same vertex stays the lowest one within ``touch`` of the ground
      (a flat sole has many lowest vertices; switching between them is not a slide);
    - ``grounded``: the sum over frames of the largest horizontal step of any foot vertex
      that touches the ground (within ``touch``) in both frames: grounded skin must not
      skate.

    Returns (lowest, grounded, contact fraction per foot).
    """
    clip = rig.clips[clip_name]
    times = np.arange(int(round(clip.duration * fps)) + 1) / fps
    b = rig.binding
    main = b.indices[np.arange(len(b.indices)), np.argmax(b.weights, axis=1)]
    ground = rig.vertices[:, 1].min()
    ids = {f: np.flatnonzero(main == rig.skeleton.joint_index(f)) for f in foot_joints}
    frames = {f: [] for f in foot_joints}
    for t in times:
        v = rig.skin(clip.sample(t))
        for f, sel in ids.items():
            frames[f].append(v[sel])
    lowest = grounded = 0.0
    frac = {}
    for f, vs in frames.items():
        vs = np.array(vs) - [0, ground, 0]                 # (T, n, 3), heights above ground
        low = vs[:, :, 1].min(axis=1)
        on = low < contact
        frac[f] = on.mean()
        start = None
        for i, c in enumerate(np.r_[on, False]):
            if c and start is None:
                start = i
            elif not c and start is not None:
                seg = vs[start:i]
                k = np.argmin(seg[0, :, 1])
                keep = seg[:, k, 1] < touch
                n_keep = len(keep) if keep.all() else int(np.argmin(keep))
                if n_keep:
                    p = seg[:n_keep, k][:, [0, 2]]
                    lowest = max(lowest, np.linalg.norm(p - p[0], axis=1).max())
                total = 0.0
                for a, bb in zip(seg[:-1], seg[1:]):
                    both = (a[:, 1] < touch) & (bb[:, 1] < touch)
                    if both.any():
                        total += np.linalg.norm((bb - a)[both][:, [0, 2]], axis=1).max()
                grounded = max(grounded, total)
                start = None
    return lowest, grounded, frac


# Limits about 1.5x what the bundled clips measure now (foot_slide at 120 samples/s), so a
# regression in the clips or the weights shows; the measured value is beside each limit.
HOOVES = [f"{p}_hoof_{s}" for p in ("hind", "fore") for s in "LR"]


@pytest.mark.parametrize("clip, max_lowest, max_grounded, duty", [
    # measured: walk 1.34 mm, 2.37 mm, duty 0.655-0.669 (built 0.62);
    ("walk", 0.0020, 0.0036, (0.62, 0.70)),
    # trot: 2.24 mm, 13.36 mm, duty 0.452-0.466 (built 0.4)
    ("run", 0.0034, 0.020, (0.42, 0.50))])
def test_quadruped_hooves_stay_planted(quad, clip, max_lowest, max_grounded, duty):
    lowest, grounded, frac = foot_slide(quad, clip, HOOVES)
    assert lowest < max_lowest, f"hoof slides {lowest * 1000:.2f} mm"
    assert grounded < max_grounded, f"hoof skates {grounded * 1000:.2f} mm"
    for f, x in frac.items():   # each hoof's share of the cycle on the ground
        assert duty[0] < x < duty[1], (f, x)


def test_quadruped_walk_is_four_beat(quad):
    """Touchdowns in the order LH, LF, RH, RF, a quarter cycle apart."""
    clip = quad.clips["walk"]
    sk = quad.skeleton
    n = 240
    times = np.linspace(0, clip.duration, n + 1)
    pos = np.array([quad.joint_matrices(clip.sample(t))[:, :3, 3] for t in times])
    down = {}
    for f in ("hind_hoof_L", "fore_hoof_L", "hind_hoof_R", "fore_hoof_R"):
        step = np.linalg.norm(np.diff(pos[:, sk.joint_index(f)], axis=0), axis=1)
        still = step < 2e-4          # under 5 cm/s: planted
        # The planted phase is the longest run of still samples (circular); it starts at
        # the touchdown.
        starts = np.flatnonzero(still & ~np.roll(still, 1))
        runs = [np.argmax(~np.roll(still, -int(a))) for a in starts]
        assert len(starts) >= 1, f
        down[f] = starts[int(np.argmax(runs))] / n
    order = sorted(down, key=down.get)
    start = order.index("hind_hoof_L")
    assert order[start:] + order[:start] == ["hind_hoof_L", "fore_hoof_L", "hind_hoof_R",
                                               "fore_hoof_R"]
    gaps = np.diff(sorted(down.values()))
    # measured: gaps 0.267, 0.233, 0.267 (4 of the 240 samples off a quarter)
    assert np.allclose(gaps, 0.25, atol=0.02), down


def test_humanoid_walk_feet_stay_planted(human):
    feet = ["LeftFoot", "RightFoot", "LeftToeBase", "RightToeBase"]
    lowest, grounded, frac = foot_slide(human, "walk", feet)
    assert lowest < 0.0028, f"foot slides {lowest * 1000:.2f} mm"      # measured 1.89 mm
    assert grounded < 0.0083, f"foot skates {grounded * 1000:.2f} mm"  # measured 5.56 mm
    for f in ("LeftToeBase", "RightToeBase"):   # ball of the foot down: measured 0.684-0.692
        assert 0.64 < frac[f] < 0.74, (f, frac[f])


# Measured over 7 samples of every clip: the worst stretch of one mesh edge (posed minus rest
# length) and the 99.9th percentile of posed/rest edge length. The worst edges are where
# linear blend skinning tears between regions that never mix: the quadruped's right armpit in
# the run (spine_2/3 against fore_upper_R: 7 mm -> 98 mm), the humanoid's crotch in the walk
# (LeftUpLeg against RightUpLeg: 4 mm -> 84 mm). Limits 1.5x the measured values.
EDGE_LIMITS = {"quadruped": (0.127, 9.9),   # measured 84.4 mm, 6.59
               "humanoid": (0.119, 4.3)}    # measured 79.2 mm, 2.88


def test_skinning_keeps_limbs_attached(rig):
    """No vertex flies off: in every sampled frame the mesh's edges stretch no more than
    they do today."""
    e = np.concatenate([rig.faces[:, [0, 1]], rig.faces[:, [1, 2]], rig.faces[:, [2, 0]]])
    rest_len = np.linalg.norm(rig.vertices[e[:, 0]] - rig.vertices[e[:, 1]], axis=1)
    max_stretch, max_ratio = EDGE_LIMITS[rig.name]
    for clip in rig.clips.values():
        for t in np.linspace(0, clip.duration, 7):
            v = rig.skin(clip.sample(t))
            length = np.linalg.norm(v[e[:, 0]] - v[e[:, 1]], axis=1)
            assert (length - rest_len).max() < max_stretch, (clip.name, t)
            assert np.percentile(length / rest_len, 99.9) < max_ratio, (clip.name, t)
