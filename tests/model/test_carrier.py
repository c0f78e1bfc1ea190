"""Carrier roots (rigedit.model.carrier): found from structure and motion, never from names;
left out of the BVH unit guess, the humanoid slots and the retarget's map."""
import warnings

import numpy as np
import pytest

from bvh_figures import HIPS_HEIGHT, humanoid_bvh
from rigedit.io.bvh import load_bvh
from rigedit.model.carrier import carrier_joints, carrier_note, figure_root
from rigedit.rigging import retarget_result
from rigedit.rigging.retarget.measure import direction_errors, lowest_foot

# a small body (metres, Y up): the hips, a left leg of three joints, a right one of two, a
# spine and a head; CARRIED hangs it under a carrier (joint 0), hips joint 1
BODY = np.array([[0, 0.95, 0], [0.1, 0.9, 0], [0.1, 0.45, 0], [0.1, 0.0, 0],
                 [-0.1, 0.9, 0], [-0.1, 0.0, 0], [0, 1.3, 0], [0, 1.7, 0]])


def _figure(hips_at, root_at):
    """Joints of a carrier at ``root_at`` above the body with its hips at ``hips_at``."""
    return np.vstack([root_at, BODY - BODY[0] + hips_at])


CARRIED = np.array([-1, 0, 1, 2, 3, 1, 5, 1, 7])


def test_far_static_carrier_found():
    """Bandai's dataset-2 walk: the root stays at the origin, the figure walks 5 m away."""
    poses = np.stack([_figure([0, 0.95, -5 + 0.1 * k], [0, 0, 0]) for k in range(20)])
    assert carrier_joints(CARRIED, poses).tolist() == [True] + [False] * 8
    note = carrier_note([f"j{k}" for k in range(9)], CARRIED, poses,
                        carrier_joints(CARRIED, poses))
    assert note.startswith("carrier root j0 (3.2-5.1 m from j1)")


def test_floor_carrier_under_the_hips_found():
    """Bandai's dataset-1, iClone's RL_BoneRoot, the bundled humanoid's root: on the floor
    under the hips, travelling with them."""
    pose = _figure([0, 0.95, 2.0], [0, 0, 2.0])
    assert carrier_joints(CARRIED, pose)[0]
    assert figure_root(CARRIED, carrier_joints(CARRIED, pose)) == 1


@pytest.mark.parametrize("root_at", [[0, 0.95, 0], [0, 0.6, 0.05], [0, 1.1, 0]])
def test_root_inside_the_figure_is_no_carrier(root_at):
    """A root at the pelvis (its one child a hips joint) is part of the body."""
    assert not carrier_joints(CARRIED, _figure([0, 0.95, 0], root_at)).any()


def test_branching_root_and_plain_chain_are_no_carriers():
    # the hips as root (three children): never a carrier, wherever it is
    assert not carrier_joints(CARRIED[1:] - 1, _figure([0, 0.95, 0], [0, 0, 0])[1:]).any()
    # a chain with no branch is a figure of its own, not a carried one
    chain = np.array([-1, 0, 1, 2])
    assert not carrier_joints(chain, [[0, 0, 0], [0, 1, 0], [0, 1.5, 0], [0, 1.7, 0]]).any()


def test_carrier_needs_half_the_frames():
    """A root that sits under the figure in a few frames only (the figure passing over the
    origin) but inside its bounds in most is no carrier."""
    inside = [_figure([0, 0.95, 0], [0, 0.95, 0.0]) for _ in range(8)]
    under = [_figure([0, 0.95, 0], [0, 0, 0]) for _ in range(2)]
    assert not carrier_joints(CARRIED, np.stack(inside + under))[0]
    assert carrier_joints(CARRIED, np.stack(inside[:2] + under * 4))[0]


def _load(text, tmp_path, **kw):
    path = tmp_path / "carried.bvh"
    path.write_text(text)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rig = load_bvh(path, **kw)
    return rig, [str(w.message) for w in caught]


def test_bvh_carrier_5m_away_units_and_map(tmp_path, humanoid):
    """The issue's walk: a carrier root at the origin, the figure starting 5.4 m from it.
    Counted in, the figure was 5.2 m "tall" (guessed millimetres in the real file: a 10 cm
    figure) and the humanoid slots found no legs a quarter of its size long."""
    rig, said = _load(humanoid_bvh(carrier="joint_Root", start=(0, 0, -540)), tmp_path)
    sk = rig.skeleton
    assert "guessed centimetres" in said[0] and "NOT SURE" not in said[0]
    assert "carrier root joint_Root left out" in rig.notes["units"]
    assert "joint_Root" in rig.notes["carrier"]
    assert not sk.deform[sk.joint_index("joint_Root")] and sk.deform[1:].all()
    hips = rig.joint_matrices(rig.clips["take"].sample(0.0))[sk.joint_index("Hips"), :3, 3]
    assert np.allclose(hips, [0, HIPS_HEIGHT / 100, -5.4])
    res = retarget_result(rig, "take", humanoid)
    # every joint of the figure maps, legs included; the carrier onto the target's carrier
    assert set(res.mapping) == set(sk.names)
    assert res.mapping["joint_Root"] == "root"
    for part in ("LeftUpLeg", "LeftLeg", "RightUpLeg", "RightLeg", "LeftArm", "RightArm"):
        assert part in res.mapping
    err = direction_errors(res)
    assert err["arms"] < 0.1 and err["spine"] < 0.1, err
    assert lowest_foot(res) > -0.01


def test_bvh_carrier_in_millimetres(tmp_path):
    """The same file in millimetres: 1720 units, the carrier left out."""
    rig, said = _load(humanoid_bvh(carrier="joint_Root", start=(0, 0, -540), unit=10.0),
                      tmp_path)
    assert "guessed millimetres" in said[0] and "1.73 m" in said[0]


def test_render_frames_and_follows_the_figure_not_the_carrier(tmp_path):
    """rigedit render of the carrier-root walk framed the static carrier and the whole 2.4 m
    path (a small figure at the edge): the camera follows the hips, the carrier is left out."""
    from rigedit.render.camera import figure_joints, rest_points, swept_points

    rig, _ = _load(humanoid_bvh(carrier="joint_Root", start=(0, 0, -540)), tmp_path)
    clip = rig.clips["take"]
    carriers, follow = figure_joints(rig, clip)
    assert carriers.tolist() == [True] + [False] * (len(carriers) - 1)
    assert rig.skeleton.names[follow] == "Hips"   # the carrier stays behind
    times = np.arange(0, clip.duration, 1 / 30)
    pts = swept_points(rig, clip, times)
    extent = np.ptp(pts, axis=0)
    assert extent.max() < 1.9, extent            # the figure, followed: not 5.4 m or 2.4 m
    assert np.all(pts[:, 2] < -4.5)              # never the carrier at the origin
    assert np.ptp(rest_points(rig), axis=0).max() < 4.0   # its walk, not the origin too


def test_camera_follows_a_carrier_that_travels_with_the_figure(humanoid):
    """The bundled humanoid's root walks on the floor under its hips: the camera follows it
    (smoother than the hips' sway), and it is not framed."""
    from rigedit.render.camera import figure_joints

    carriers, follow = figure_joints(humanoid, humanoid.clips["walk"])
    assert humanoid.skeleton.names[follow] == "root" and carriers[follow]


def test_cli_render_of_a_far_carrier_walk_frames_the_figure(tmp_path):
    """The rendered figure is big and centred in every frame: its bones' pixels span most of
    the picture's height (before: framed with the carrier 5.4 m away, the figure a third of
    the picture high, near its top)."""
    import imageio.v2 as imageio

    from rigedit.cli.main import main

    src = tmp_path / "far.bvh"
    src.write_text(humanoid_bvh(carrier="joint_Root", start=(0, 0, -540)))
    out = tmp_path / "far.gif"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["render", "take", "--rig", str(src), "-o", str(out), "--size",
                     "160x120", "--fps", "3", "-q"]) == 0
    for frame in imageio.mimread(out):
        f = frame[..., :3].astype(int)
        rows, cols = np.nonzero(f[..., 2] > f[..., 0] + 60)   # the bones: blue
        lo, hi = np.percentile(rows, [5, 95])   # (not a stray dot at the origin)
        assert hi - lo > 0.5 * f.shape[0], (lo, hi)
        assert abs(np.median(cols) - f.shape[1] / 2) < 0.2 * f.shape[1]
