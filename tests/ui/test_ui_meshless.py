"""A rig without a mesh (a BVH skeleton) in the editor: bones and joint spheres, drags,
keys, playback, recording."""
import numpy as np
import pytest

from rigedit.io.bvh import load_bvh
from ui_window_fixture import editor_window

pytestmark = [pytest.mark.ui, pytest.mark.filterwarnings("error::RuntimeWarning")]

BVH = """HIERARCHY
ROOT Hips
{
  OFFSET 0 90 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0 20 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT Head
    {
      OFFSET 0 40 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      End Site
      {
        OFFSET 0 20 0
      }
    }
  }
  JOINT LeftLeg
  {
    OFFSET 10 0 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT LeftFoot
    {
      OFFSET 0 -45 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      End Site
      {
        OFFSET 0 -40 5
      }
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.5
0 90 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0
0 95 10 0 0 0 0 20 0 0 0 0 30 0 0 0 0 0
0 90 20 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0
"""


@pytest.fixture
def bvh_window(qtbot, tmp_path):
    path = tmp_path / "walk.bvh"
    path.write_text(BVH)
    rig = load_bvh(path, scale=0.01)
    with editor_window(qtbot, rig) as w:
        yield w




def test_opens_with_bones_spheres_and_no_mesh(bvh_window):
    w = bvh_window
    rig = w.document.rig
    assert w.scene.mesh_actor is None and w.scene.mesh.n_points == 0
    assert len(w.gizmos) == len(rig.skeleton) == 5
    # the first frame of the motion is shown, not the rest pose
    first = rig.joint_matrices(rig.clips["take"].sample(0.0))[:, :3, 3]
    np.testing.assert_allclose(w.gizmos.center(0), first[0], atol=1e-9)
    np.testing.assert_allclose(w.scene.bones.points, first, atol=1e-6)
    assert w.info_panel.labels["Vertices"].text() == "0"
    assert not w.weights_action.isEnabled()
    w.set_weights_view(True)  # asked anyway: nothing to paint, nothing breaks
    assert not w.scene.weights_shown
    # the 3D view shows something besides the background: bones drawn
    img = w.plotter.screenshot(return_img=True)
    assert np.ptp(img.reshape(-1, img.shape[-1])[:, :3], axis=0).max() > 50


def test_drag_a_joint_key_it_and_play(bvh_window, qtbot):
    w = bvh_window
    doc = w.document
    rig = doc.rig
    sk = rig.skeleton
    head, spine = sk.joint_index("Head"), sk.joint_index("Spine")
    w.chain_length = 1
    w.timeline.set_time(1.0)  # the last frame
    start = w.gizmos.center(head).copy()
    w.gizmos.drag(head, start + np.array([0.3, 0.0, 0.0]))
    assert len(doc.undo_stack) == 1 and doc.selection == head
    dragged = rig.joint_matrices(doc.pose)[:, :3, 3]
    assert dragged[head, 0] > start[0] + 0.05  # the head swung towards the drag
    # a rotation, not a stretch: the bone keeps its length
    assert np.isclose(np.linalg.norm(dragged[head] - dragged[spine]), 0.4, atol=1e-6)
    # the head's End Site rides along the bone: 0.2 further in the spine -> head direction
    tails = w.scene.bare_skeleton.tails.points
    tail = tails[len(tails) // 2]
    np.testing.assert_allclose(tail, dragged[head] + 0.5 * (dragged[head] - dragged[spine]),
                               atol=1e-6)
    # key it at 1 s (the drag turned the spine: key all joints), scrub away and back: the
    # keys hold the dragged pose
    w.timeline.keys.insert_key(all_joints=True)
    w.timeline.set_time(0.0)
    assert np.abs(rig.joint_matrices(doc.pose)[head, :3, 3] - dragged[head]).max() > 0.05
    w.timeline.set_time(1.0)
    np.testing.assert_allclose(rig.joint_matrices(doc.pose)[:, :3, 3], dragged, atol=1e-6)
    # playback moves the skeleton on screen
    w.timeline.set_time(0.0)
    before = w.scene.bones.points.copy()
    w.timeline.play()
    qtbot.waitUntil(lambda: np.abs(w.scene.bones.points - before).max() > 1e-3, timeout=5000)
    w.timeline.pause()


def test_record_video_of_a_skeleton(bvh_window, tmp_path):
    import imageio.v2 as imageio

    out = tmp_path / "take.gif"
    n = bvh_window.record_video(out, fps=6, size=(160, 120))
    frames = imageio.mimread(out)
    assert n == len(frames) == 6
    assert np.abs(frames[0].astype(int) - frames[3].astype(int)).max() > 50


def test_file_open_bvh_and_export_bvh(bvh_window, qtbot, tmp_path):
    w = bvh_window
    src = tmp_path / "other.bvh"
    src.write_text(BVH.replace("OFFSET 0 40 0", "OFFSET 0 30 0"))
    w.files.open_file(str(src))
    qtbot.waitUntil(lambda: w.document.rig.name == "other", timeout=10000)
    rig = w.document.rig
    assert "units: guessed centimetres" in w.statusBar().currentMessage()
    assert len(w.gizmos) == 5 and w.scene.mesh_actor is None
    out = tmp_path / "out.bvh"
    assert w.files.export(str(out))
    back = load_bvh(out, scale=0.01)
    clip, back_clip = rig.clips["take"], back.clips["take"]
    for t in (0.0, 0.5, 1.0):
        np.testing.assert_allclose(back.joint_matrices(back_clip.sample(t))[:, :3, 3],
                                   rig.joint_matrices(clip.sample(t))[:, :3, 3], atol=1e-7)
    # a broken file: one message, the current rig stays
    bad = tmp_path / "bad.bvh"
    bad.write_text(BVH.replace("MOTION", "MOTIONLESS"))
    w.files.open_file(str(bad))
    qtbot.waitUntil(lambda: w.last_error is not None, timeout=10000)
    assert "bad.bvh" in str(w.last_error) and "MOTION" in str(w.last_error)
    assert w.document.rig is rig


def test_edit_mode_moves_a_rest_joint_of_a_skeleton(bvh_window, qtbot):
    """Bind mode on a rig without a mesh: the rest joint moves (nothing to re-weight), one
    undo step."""
    w = bvh_window
    doc = w.document
    sk0 = doc.skeleton
    foot = sk0.joint_index("LeftFoot")
    w.set_mode("edit")
    start = w.gizmos.center(foot).copy()
    target = start + np.array([0.05, 0.0, 0.0])
    w.gizmos.drag(foot, target)
    qtbot.waitUntil(lambda: w.job is None, timeout=30000)
    assert doc.skeleton is not sk0
    np.testing.assert_allclose(doc.skeleton.bind_matrices[foot, :3, 3], target, atol=1e-9)
    assert doc.rig.binding.indices.shape[0] == 0
    w.undo_action.trigger()
    assert doc.skeleton is sk0
    w.set_mode("pose")
