"""BVH in: poses checked against an independent reading of the format written here."""
from testpaths import REPO
import warnings
from pathlib import Path

import numpy as np
import pytest

import rigedit
from rigedit.errors import RigFileError
from rigedit.io.bvh import BvhUnitsWarning, believable, guess_unit, load_bvh

DATA = REPO.parent / "shared" / "data"
FILES = ["bvh-cmu/131_01.bvh", "bvh-bandai/dataset-1_walk_normal_002.bvh",
         "bvh-bandai/dataset-1_run_normal_001.bvh"]


def shared(name):
    path = DATA / name
    if not path.is_file():
        pytest.skip(f"shared test data not found: {path}")
    return path


# ---------------------------------------------------------------- an independent reader
def _axis_matrix(axis, degrees):
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    return {"X": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "Y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "Z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


def reference_positions(path, frames_wanted):
    """Joint positions per wanted frame: {name: (len(frames_wanted), 3)} in file units.

    A recursive parser over whitespace tokens; each joint's local 4x4 is T(offset with
    position channels substituted) times the rotation channels' matrices in listed order.
    """
    text = Path(path).read_text()
    head, motion = text.split("MOTION")
    tokens = head.replace("{", " { ").replace("}", " } ").split()
    joints = []  # (name, parent index, offset, channel list)

    def joint(pos, parent):
        name = tokens[pos]
        assert tokens[pos + 1] == "{"
        pos += 2
        me = len(joints)
        joints.append([name, parent, None, []])
        while tokens[pos] != "}":
            if tokens[pos] == "OFFSET":
                joints[me][2] = np.array([float(v) for v in tokens[pos + 1:pos + 4]])
                pos += 4
            elif tokens[pos] == "CHANNELS":
                n = int(tokens[pos + 1])
                joints[me][3] = tokens[pos + 2:pos + 2 + n]
                pos += 2 + n
            elif tokens[pos] == "JOINT":
                pos = joint(pos + 1, me)
            elif tokens[pos] == "End":
                pos += 7  # End Site { OFFSET x y z }
                assert tokens[pos] == "}"
                pos += 1
        return pos + 1

    pos = tokens.index("ROOT") + 1
    joint(pos, -1)
    lines = [line for line in motion.splitlines() if line.strip()]
    values = [np.array(lines[2 + k].split(), dtype=float) for k in frames_wanted]
    out = {name: np.zeros((len(frames_wanted), 3)) for name, *_ in joints}
    for f, row in enumerate(values):
        world = []
        col = 0
        for name, parent, offset, channels in joints:
            t, r = offset.copy(), np.eye(3)
            for ch in channels:
                if ch.endswith("position"):
                    t["XYZ".index(ch[0])] = row[col]
                else:
                    r = r @ _axis_matrix(ch[0], row[col])
                col += 1
            local = np.eye(4)
            local[:3, :3], local[:3, 3] = r, t
            world.append(local if parent < 0 else world[parent] @ local)
            out[name][f] = world[-1][:3, 3]
    return out


@pytest.mark.parametrize("name", FILES)
def test_pose_at_frame_k_equals_independent_reading(name):
    path = shared(name)
    rig = load_bvh(path, scale=1.0)  # file units on both sides
    clip = rig.clips["take"]
    n = len(clip.tracks[(rig.skeleton.names[0], "rotation")].times)
    wanted = [0, 1, n // 3, n // 2, n - 2, n - 1]
    ref = reference_positions(path, wanted)
    frame_time = float(Path(path).read_text().split("Frame Time:")[1].split()[0])
    ref_all = np.concatenate([ref[j] for j in rig.skeleton.names])
    height = np.ptp(ref_all[:, 1])
    worst = 0.0
    for f, k in enumerate(wanted):
        got = rig.joint_matrices(clip.sample(k * frame_time))[:, :3, 3]
        want = np.array([ref[j][f] for j in rig.skeleton.names])
        worst = max(worst, np.abs(got - want).max())
    assert height > 10  # a figure, not a point (CMU: about 24 units, Bandai: about 150)
    assert worst <= 1e-6 * height, (worst, height)


def test_skeleton_and_clip_shape_from_the_file():
    path = shared(FILES[0])
    with pytest.warns(BvhUnitsWarning, match="CMU units"):
        rig = rigedit.load_rig(path)
    assert rig.vertices.shape == (0, 3) and rig.faces.shape == (0, 3)
    assert len(rig.skeleton) == 31 and rig.skeleton.names[0] == "Hips"
    clip = rig.clips["take"]
    assert np.isclose(clip.duration, 993 * 0.0083333)
    assert not clip.loop
    # only the root has position channels; every joint has rotation channels
    assert {j for j, ch in clip.tracks if ch == "translation"} == {"Hips"}
    assert sum(ch == "rotation" for _, ch in clip.tracks) == 31
    # End Site: LeftToe's tail is its head plus the End Site offset (0, 0, 1.13491) units
    toe = rig.skeleton.joint_index("LeftToe")
    assert np.allclose(rig.skeleton.tails[toe] - rig.skeleton.bind_matrices[toe, :3, 3],
                       np.array([0, 0, 1.13491]) * (0.0254 / 0.45))
    assert "CMU" in rig.notes["units"] and "Y up" in rig.notes["frames"]


@pytest.mark.parametrize("size,unit", [(170, "centimetres"), (150, "centimetres"),
                                        (190, "centimetres"), (1.75, "metres"),
                                        (1800, "millimetres"), (68, "inches"),
                                        (30, "CMU units (1/0.45 inch)")])
def test_unit_guess(size, unit):
    assert guess_unit(size)[0] == unit


SMALL = """HIERARCHY
ROOT root
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT mid
  {
    OFFSET 0 100 0
    CHANNELS 3 Yrotation Xrotation Zrotation
    JOINT top
    {
      OFFSET 0 50 0
      CHANNELS 2 Zrotation Yposition
      End Site
      {
        OFFSET 0 20 0
      }
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.5
0 10 0 0 0 0 90 0 0 0 50
1 10 0 0 0 0 0 0 0 0 80
2 10 0 90 0 0 0 0 0 0 50
"""


def write(tmp_path, text, name="s.bvh"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_small_file_exact_positions(tmp_path):
    rig = load_bvh(write(tmp_path, SMALL), scale=0.01)
    clip = rig.clips["take"]
    assert clip.duration == 1.0
    p0 = rig.joint_matrices(clip.sample(0.0))[:, :3, 3]
    # mid turned 90 degrees about y: top stays straight above
    assert np.allclose(p0, [[0, .1, 0], [0, 1.1, 0], [0, 1.6, 0]])
    p1 = rig.joint_matrices(clip.sample(0.5))[:, :3, 3]
    # top's Yposition 80 replaces its offset 50
    assert np.allclose(p1, [[.01, .1, 0], [.01, 1.1, 0], [.01, 1.9, 0]])
    p2 = rig.joint_matrices(clip.sample(1.0))[:, :3, 3]
    # root rolled 90 degrees about z: the chain points along -x
    assert np.allclose(p2, [[.02, .1, 0], [-.98, .1, 0], [-1.48, .1, 0]])
    # the interpolated pose halfway between frames 0 and 1 is halfway for translation
    ph = rig.joint_matrices(clip.sample(0.25))[:, :3, 3]
    assert np.allclose(ph[2], [.005, 1.75, 0])
    assert np.allclose(rig.skeleton.tails[2], [0, 1.7, 0])


def test_guess_is_reported_and_scale_wins(tmp_path):
    path = write(tmp_path, SMALL)
    with pytest.warns(BvhUnitsWarning, match="centimetres"):
        rig = load_bvh(path)
    assert np.allclose(rig.skeleton.rest_translation[1], [0, 1, 0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rig = load_bvh(path, scale=0.001)
    assert np.allclose(rig.skeleton.rest_translation[1], [0, 0.1, 0])
    assert "given" in rig.notes["units"]


@pytest.mark.parametrize("change,line,problem", [
    (lambda t: t.replace("MOTION\n", ""), None, "expected a MOTION section"),
    (lambda t: t.replace("1 10 0 0 0 0 0 0 0 0 80", "1 10 0 0 0 0 0 0 0 80"), 25,
     "expected 11 numbers (one per channel), got 10"),
    (lambda t: t.replace("Yrotation Xrotation Zrotation", "Yrotation Xrotation Wrotation"), 9,
     "expected a channel name"),
    (lambda t: t.replace("0 10 0 0 0 0 90", "0 ten 0 0 0 0 90"), 24, "expected numbers, got 'ten'"),
    (lambda t: t.replace("Frame Time: 0.5", "Frame Time: -0.5"), 23, "Frame Time > 0"),
    (lambda t: t.replace("Frame Time: 0.5", "Frame Time: 0"), 23, "Frame Time > 0"),
    (lambda t: t.replace("OFFSET 0 20 0\n      }", "OFFSET 0 20 0\n"), 20, "without its '}'"),
    (lambda t: t.replace("}\nMOTION", "}\n}\nMOTION"), 21, "expected ROOT or MOTION, got '}'"),
    (lambda t: t.split("Frames")[0], 22, "expected 'Frames:', got the end of the file"),
    (lambda t: t.replace("2 10 0 90", "2 nan 0 90"), 26, "finite"),
    (lambda t: t.replace("OFFSET 0 50 0", "OFFSET 0 inf 0"), 12, "finite"),
    (lambda t: t.replace("Frames: 3", "Frames: 4"), None, "expected 4 frame lines"),
    (lambda t: t.replace("Frames: 3", "Frames: x"), 22, "expected a number after 'Frames:'"),
    (lambda t: t.replace("HIERARCHY", "HIERARCH"), 1, "expected 'HIERARCHY'"),
    (lambda t: t.replace("JOINT top", "JOINT mid"), 10, "unique joint names"),
])
def test_bad_bvh_names_file_and_line(tmp_path, change, line, problem):
    path = write(tmp_path, change(SMALL), "bad.bvh")
    with pytest.raises(RigFileError) as info:
        load_bvh(path, scale=0.01)
    msg = str(info.value)
    assert msg.startswith(str(path)) and problem in msg, msg
    if line is not None:
        assert f"line {line}:" in msg, msg


def test_cli_bad_bvh_is_one_line_exit_2(tmp_path, capsys):
    from rigedit.cli.main import main

    path = write(tmp_path, SMALL.replace("MOTION\n", ""), "bad.bvh")
    assert main(["info", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"rigedit: error: {path}: expected a MOTION section, got none"]


@pytest.mark.parametrize("seq", ["ZXY", "XYZ", "YZX", "ZYX", "X", "YX", "ZXZ"])
def test_euler_channels_match_scipy_intrinsic(seq):
    from scipy.spatial.transform import Rotation
    from rigedit.io.bvh import euler_channels_to_quats

    angles = np.random.default_rng(1).uniform(-180, 180, (50, len(seq)))
    got = euler_channels_to_quats(angles, ["XYZ".index(a) for a in seq])
    want = Rotation.from_euler(seq, angles, degrees=True)
    assert np.allclose((Rotation.from_quat(got).inv() * want).magnitude(), 0, atol=1e-12)


def test_windows_line_ends_tabs_and_a_byte_order_mark(tmp_path):
    text = "\ufeff" + SMALL.replace("\n", "\r\n").replace("  ", "\t")
    path = tmp_path / "win.bvh"
    path.write_bytes(text.encode("utf-8"))
    rig = load_bvh(path, scale=0.01)
    np.testing.assert_allclose(rig.joint_matrices(rig.clips["take"].sample(1.0))[:, :3, 3],
                               [[.02, .1, 0], [-.98, .1, 0], [-1.48, .1, 0]], atol=1e-12)


@pytest.mark.parametrize("argv,problem", [
    (["info", "{bvh}", "--scale", "-1"], "expected a scale > 0"),
    (["info", "{folder}", "--scale", "0.01"], "only with a .bvh file"),
])
def test_cli_scale_errors(tmp_path, capsys, argv, problem):
    from rigedit.cli.main import main

    bvh = write(tmp_path, SMALL)
    folder = tmp_path / "folder"
    folder.mkdir()
    argv = [a.format(bvh=bvh, folder=folder) for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and problem in err[0]


TWO_ROOTS = """HIERARCHY
ROOT a
{
  OFFSET 0 0 0
  CHANNELS 3 Xposition Yposition Zposition
  JOINT a1
  {
    OFFSET 0 10 0
    CHANNELS 0
    End Site
    {
      OFFSET 0 5 0
    }
  }
}
ROOT b
{
  OFFSET 50 0 0
  CHANNELS 1 Yrotation
  End Site
  {
    OFFSET 10 0 0
  }
}
MOTION
Frames: 2
Frame Time: 0.1
0 0 0 0
5 0 0 90
"""


def test_several_roots_and_joints_without_channels_round_trip(tmp_path):
    from rigedit.io.bvh_write import save_bvh

    rig = load_bvh(write(tmp_path, TWO_ROOTS), scale=0.01)
    sk = rig.skeleton
    assert list(sk.parents) == [-1, 0, -1]
    clip = rig.clips["take"]
    assert set(clip.tracks) == {("a", "translation"), ("b", "rotation")}
    end = rig.joint_matrices(clip.sample(0.1))
    np.testing.assert_allclose(end[:, :3, 3], [[.05, 0, 0], [.05, .1, 0], [.5, 0, 0]])
    # b turned 90 degrees about y: its End Site (10 units along x) now points along -z
    joints, tails = rig.posed_tails(end)
    np.testing.assert_allclose(tails[list(joints).index(2)], [.5, 0, -.1], atol=1e-12)
    out = tmp_path / "out.bvh"
    save_bvh(rig, out)
    back = load_bvh(out, scale=0.01)
    assert back.skeleton.names == sk.names
    for t in (0.0, 0.1):
        np.testing.assert_allclose(back.joint_matrices(back.clips["take"].sample(t))[:, :3, 3],
                                   rig.joint_matrices(clip.sample(t))[:, :3, 3], atol=1e-8)


@pytest.mark.parametrize("size,unit", [(125, "centimetres"), (215, "centimetres"),
                                        (48, "inches"), (22, "CMU units (1/0.45 inch)")])
def test_unit_guess_takes_the_unit_that_makes_a_human(size, unit):
    """Within 1.2-2.2 m at most one unit fits: it wins even far from 1.7 m (125 cm used to
    read as inches: 3.2 m)."""
    name, scale = guess_unit(size)
    assert name == unit and believable(size * scale)


def test_unit_guess_outside_a_human_size_says_not_sure(tmp_path):
    """A figure 4 m in centimetres or 0.4 m in millimetres: no unit makes it a human."""
    text = SMALL.replace("OFFSET 0 100 0", "OFFSET 0 330 0")   # about 420 units across
    with pytest.warns(BvhUnitsWarning, match="NOT SURE: no unit makes it a human's 1.2-2.2 m"):
        rig = load_bvh(write(tmp_path, text))
    assert "NOT SURE" in rig.notes["units"] and "units across): 4.2" in rig.notes["units"]


@pytest.mark.parametrize("name", sorted(str(p.relative_to(DATA))
                                        for p in DATA.glob("**/*.bvh")))
def test_every_shared_bvh_is_read_as_a_human(name):
    """Every shared BVH (Bandai's dataset-2 walk with its carrier 5 m away included) reads
    as centimetres or CMU units, a human's size, unflagged; a carrier root is named."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rig = load_bvh(shared(name))
    note = rig.notes["units"]
    assert ("centimetres" in note or "CMU units" in note) and "NOT SURE" not in note, note
    assert len(caught) == 1
    root = rig.skeleton.names[0]
    assert ("carrier" in rig.notes) == (root in ("joint_Root", "RL_BoneRoot")), rig.notes
