"""Frames: axis changes of skeleton and clips together, and the elk layout's Z-up skeleton
over a Y-up mesh."""
import json
import warnings

import numpy as np
import pytest

import rigedit
from builders import chain_skeleton, cylinder
from rigedit.animation import Clip, Track
from rigedit.cli.main import main
from rigedit.io.frames import FramesWarning, Z_UP_TO_Y_UP, axis_change, change_axes
from rigedit.model import Skeleton
from rigedit.model.transforms import euler_to_quat
from rigedit.rig import Rig


def _rig_with_everything(spline=True):
    """A bent cylinder whose skeleton has rest rotations and a rest scale, with rotation
    (slerp, Catmull-Rom, and a cubic spline unless ``spline`` is false), translation and
    scale tracks."""
    base = chain_skeleton(3)
    rest_rot = euler_to_quat([[0, 0, 10], [5, 0, 0], [0, 20, 0]], degrees=True)
    sk = Skeleton(base.names, base.parents, base.rest_translation, rest_rot,
                  [[1, 1, 1], [1.2, 0.9, 1.0], [1, 1, 1]], tails=base.tails)
    q = euler_to_quat([[0, 0, 0], [30, 0, 40], [-20, 10, 0]], degrees=True)
    tangents = np.zeros((3, 2, 4))
    tangents[1] = [[0.1, 0.0, 0.2, 0.0], [0.0, 0.3, 0.0, -0.1]]
    tracks = {
        ("j1", "rotation"): Track("rotation", [0, .5, 1], q, "slerp"),
        ("j2", "rotation"): Track("rotation", [0, .5, 1], q[::-1], "catmull_rom"),
        ("j0", "translation"): Track("translation", [0, 1], [[0, 0, 0], [0.3, 0.2, -0.1]]),
        ("j2", "scale"): Track("scale", [0, 1], [[1, 1, 1], [1.5, 0.7, 1.1]]),
    }
    if spline:
        tracks[("j0", "rotation")] = Track("rotation", [0, .5, 1], q, "cubic_spline", tangents)
    clip = Clip("mix", sk, tracks)
    v, f = cylinder()
    return Rig(sk, v, f, clips={"mix": clip})


@pytest.mark.parametrize("R", [Z_UP_TO_Y_UP, Z_UP_TO_Y_UP.T,
                               np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])])
def test_change_axes_skins_to_R_times_the_original_at_every_frame(R):
    rig = _rig_with_everything()
    sk2, clips2 = change_axes(rig.skeleton, rig.clips, R)
    rig2 = Rig(sk2, rig.vertices @ R.T, rig.faces, rig.binding.indices, rig.binding.weights,
               clips2)
    clip, clip2 = rig.clips["mix"], rig2.clips["mix"]
    assert clip2.tracks[("j0", "rotation")].interpolation == "cubic_spline"
    worst = 0.0
    for t in np.linspace(0, 1, 21):
        want = rig.skin(clip.sample(t)) @ R.T
        got = rig2.skin(clip2.sample(t))
        worst = max(worst, np.abs(got - want).max())
        joints = rig.joint_matrices(clip.sample(t))[:, :3, 3] @ R.T
        np.testing.assert_allclose(rig2.joint_matrices(clip2.sample(t))[:, :3, 3], joints,
                                   atol=1e-9)
    assert worst < 1e-5  # float32 skinning buffers
    # rotation keys are conjugated, not copied (a turn about z is one about -y after z->y)
    np.testing.assert_allclose(np.nan_to_num(sk2.tails), np.nan_to_num(rig.skeleton.tails @ R.T))
    assert not np.allclose(clip2.tracks[("j1", "rotation")].values,
                           clip.tracks[("j1", "rotation")].values)


def test_axis_change_table():
    np.testing.assert_allclose(axis_change("z", "y") @ [1, 2, 3], [1, 3, -2])
    np.testing.assert_allclose(axis_change("y", "z") @ [1, 3, -2], [1, 2, 3])
    np.testing.assert_allclose(axis_change("y", "y"), np.eye(3))


# ---------------------------------------------------------------- the elk layout
def write_elk_y_up_mesh(folder, manifest=None):
    """An elk-layout folder as Blender writes it: the skeleton's heads and tails in Blender
    world coordinates (Z up), the OBJ mesh Y up (x, z, -y), and a clip that nods the head
    about x and bobs the pelvis along +y (the seed viewer's frame)."""
    for sub in ("models", "skeleton", "animations"):
        (folder / sub).mkdir(parents=True, exist_ok=True)
    joints = [("_rootJoint", None, [0, 0, 0], [0, 0, 0]),
              ("pelvis", "_rootJoint", [0, 0, 1.0], [0, 0, 1.5]),
              ("spine", "pelvis", [0, 0, 1.5], [0, 0, 2.2]),
              ("neck", "spine", [0, 0, 2.2], [0, 0, 2.5]),
              ("head", "neck", [0, 0, 2.5], [0, 0, 3.0])]
    (folder / "skeleton" / "skeleton.json").write_text(json.dumps({"joints": [
        {"name": n, "index": i, "head": h, "tail": t, "parent": p}
        for i, (n, p, h, t) in enumerate(joints)]}))
    v, f = cylinder(radius=0.3, height=2.5)   # along +y: the Y-up export of a Z-up body
    v = v + [0, 0.5, 0]
    lines = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in v]
    lines += ["f " + " ".join(str(i + 1) for i in face) for face in f]
    (folder / "models" / "body.obj").write_text("\n".join(lines) + "\n")
    keys = {"neck": [{"time": 0.0, "rotation": [0, 0, 0]}, {"time": 0.5, "rotation": [0.6, 0, 0]},
                     {"time": 1.0, "rotation": [0, 0, 0]}],
            "pelvis": [{"time": 0.0, "translation": [0, 0, 0]},
                       {"time": 0.5, "translation": [0, 0.2, 0]},
                       {"time": 1.0, "translation": [0, 0, 0]}]}
    (folder / "animations" / "nod.json").write_text(json.dumps(
        {"name": "nod", "duration": 1.0, "keyframes": keys}))
    if manifest is not None:
        (folder / "rig.json").write_text(json.dumps(manifest))
    return folder


def _load(folder):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rig = rigedit.load_rig(folder)
    return rig, [w for w in caught if issubclass(w.category, FramesWarning)]


def test_elk_skeleton_z_up_over_y_up_mesh_is_converted_and_clips_play(tmp_path):
    rig, frames_warnings = _load(write_elk_y_up_mesh(tmp_path / "elk"))
    assert rig.up == "y"
    assert len(frames_warnings) == 1 and "(x, y, z) -> (x, z, -y)" in rig.notes["frames"]
    sk = rig.skeleton
    heads = sk.bind_matrices[:, :3, 3]
    np.testing.assert_allclose(heads[sk.joint_index("head")], [0, 2.5, 0])
    # the joints are inside the body, so the head's vertices are weighted to the neck/head
    head_verts = rig.vertices[:, 1] > 2.6
    head_side = np.isin(rig.binding.indices[head_verts, 0],
                        [sk.joint_index("neck"), sk.joint_index("head")])
    assert head_side.mean() > 0.9
    clip = rig.clips["nod"]
    rest = rig.skin(clip.sample(0.0))
    mid = rig.skin(clip.sample(0.5))
    # the head nods: its vertices move (forward/back in z and down), the legs' do not
    shift = np.linalg.norm(mid - rest, axis=1)
    assert np.median(shift[head_verts]) > 0.05
    pelvis = sk.joint_index("pelvis")
    p0 = rig.joint_matrices(clip.sample(0.0))[pelvis, :3, 3]
    p1 = rig.joint_matrices(clip.sample(0.5))[pelvis, :3, 3]
    # the pelvis bobs vertically (+y is up in the mesh's frame)
    np.testing.assert_allclose(p1 - p0, [0, 0.2, 0], atol=1e-9)
    # and the nod turns about x: the head joint swings in the y-z plane only
    h1 = rig.joint_matrices(clip.sample(0.5))[sk.joint_index("head"), :3, 3]
    assert abs(h1[0]) < 1e-9 and abs(h1[2]) > 0.1


def test_rig_json_frames_win_over_the_guess(tmp_path):
    folder = write_elk_y_up_mesh(tmp_path / "elk", {"up": "y", "skeleton_up": "y"})
    rig, frames_warnings = _load(folder)
    assert frames_warnings == [] and "stated in rig.json" in rig.notes["frames"]
    np.testing.assert_allclose(rig.skeleton.bind_matrices[-1, :3, 3], [0, 0, 2.5])
    folder = write_elk_y_up_mesh(tmp_path / "elk2", {"up": "y", "skeleton_up": "z"})
    rig, frames_warnings = _load(folder)
    assert len(frames_warnings) == 1 and "stated in rig.json" in rig.notes["frames"]
    np.testing.assert_allclose(rig.skeleton.bind_matrices[-1, :3, 3], [0, 2.5, 0])


def test_elk_folder_already_in_one_frame_is_left_alone(tmp_path):
    from builders import write_elk_folder

    rig, frames_warnings = _load(write_elk_folder(tmp_path / "elk"))
    assert frames_warnings == [] and rig.up == "z"
    assert "both Z up" in rig.notes["frames"]


def test_info_prints_the_frames_decision(tmp_path, capsys):
    folder = write_elk_y_up_mesh(tmp_path / "elk")
    assert main(["info", str(folder)]) == 0
    out = dict(line.split(": ", 1) for line in capsys.readouterr().out.splitlines())
    assert out["up"] == "y" and "converted by (x, y, z) -> (x, z, -y)" in out["frames"]


def test_rigedit_folder_with_z_up_skeleton_converts_skeleton_and_clips(tmp_path):
    """rigedit's own formats: rig.json says the skeleton is Z up over a Y-up mesh; skeleton
    and clips are converted together and the rig plays as the Y-up original."""
    from rigedit.io.clip_json import save_clip
    from rigedit.io.mesh import save_obj
    from rigedit.io.skeleton_json import save_skeleton

    rig = _rig_with_everything(spline=False)
    R = axis_change("y", "z")
    sk_z, clips_z = change_axes(rig.skeleton, rig.clips, R)
    folder = tmp_path / "r"
    (folder / "animations").mkdir(parents=True)
    save_obj(folder / "mesh.obj", rig.vertices, rig.faces)
    save_skeleton(folder / "skeleton.json", sk_z, up="z")
    save_clip(folder / "animations" / "mix.json", clips_z["mix"])
    (folder / "rig.json").write_text(json.dumps({"up": "y", "skeleton_up": "z"}))
    back, frames_warnings = _load(folder)
    assert len(frames_warnings) == 1 and "converted together" in back.notes["frames"]
    assert back.up == "y"
    for t in np.linspace(0, 1, 5):
        np.testing.assert_allclose(back.joint_matrices(back.clips["mix"].sample(t)),
                                   rig.joint_matrices(rig.clips["mix"].sample(t)), atol=1e-6)
