"""The timeline dock on a real window under Xvfb: playback in real time with skip-ahead,
scrubbing poses the mesh, keys inserted / moved / deleted / pasted with undo, auto-key, clip
management, interpolation, video export from the editor."""
import time

import imageio.v3 as iio
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

pytestmark = [pytest.mark.ui, pytest.mark.filterwarnings("error::RuntimeWarning")]

from PyQt5 import QtCore, QtWidgets  # noqa: E402

from rigedit.animation import Clip, Track  # noqa: E402

from ui_window_fixture import editor_window  # noqa: E402
from ui_window_fixture import send_mouse as _mouse  # noqa: E402


def _rig():
    from rigedit.ui.fallback import demo_rig

    rig = demo_rig()   # small: the UI tests stay fast
    sk = rig.skeleton
    j = sk.index["neck"]
    rest = Rotation.from_quat(sk.rest_rotation[j])
    q = [(rest * Rotation.from_euler("x", a, degrees=True)).as_quat() for a in (0, 50, 0)]
    rig.clips["nod"] = Clip("nod", sk, {("neck", "rotation"): Track("rotation", [0, 0.5, 1], q)},
                            duration=1.0)
    return rig


@pytest.fixture
def window(qtbot):
    with editor_window(qtbot, _rig(), size=(1000, 700)) as w:
        yield w


def _row_y(ruler, row):
    return ruler.row_y(row) + 8


def test_play_advances_in_real_time_and_pause_freezes(window, qtbot):
    tl = window.timeline
    assert tl.time == 0.0
    tl.play()
    assert tl.playing
    qtbot.waitUntil(lambda: tl.time > 0.15, timeout=3000)
    tl.pause()
    frozen = tl.time
    qtbot.wait(100)
    assert tl.time == frozen and not tl.playing


def test_a_slow_frame_skips_ahead(window, qtbot):
    tl = window.timeline
    tl.set_loop(False)
    tl.play()
    time.sleep(0.4)                      # the UI is blocked: no tick for 0.4 s
    qtbot.wait(40)                       # the next tick jumps to wall time, not + 1 frame
    assert tl.time >= 0.4
    tl.pause()


def test_one_shot_playback_stops_at_the_end(window, qtbot):
    tl = window.timeline
    tl.set_loop(False)
    tl.set_speed(4.0)
    tl.play()
    qtbot.waitUntil(lambda: not tl.playing, timeout=3000)
    assert tl.time == pytest.approx(1.0)


def test_joint_panel_refreshes_less_often_while_playing_and_shows_the_paused_pose(
        window, qtbot):
    d, tl, panel = window.document, window.timeline, window.joint_panel
    d.select(d.skeleton.index["neck"])
    shown = []
    original = panel.show_joint
    panel.show_joint = lambda j, pose: (shown.append(tl.time), original(j, pose))
    tl.play()
    tl.timer.stop()            # frames stepped by hand, faster than the panel's interval
    for i in range(50):
        tl.set_time(0.01 * i)
    assert shown == []         # while playing, none is shown at once ...
    qtbot.waitUntil(lambda: len(shown) == 1, timeout=3000)
    qtbot.wait(20)
    assert len(shown) == 1     # ... but one refresh comes, with the pose on screen
    assert shown[-1] == pytest.approx(0.49)
    tl.set_time(0.6)
    tl.pause()
    # the panel comes back to the pose on screen when playback paused
    qtbot.waitUntil(lambda: shown[-1] == pytest.approx(0.6), timeout=3000)
    np.testing.assert_allclose(panel.angles(), d.pose.get_euler(d.selection, degrees=True),
                               atol=0.05)
    # paused: every pose change shows at once again
    tl.set_time(0.25)
    assert shown[-1] == pytest.approx(0.25)


def test_a_panel_refresh_due_when_the_window_closes_does_not_run(window, qtbot):
    from rigedit.ui.main_window import PANEL_PLAYBACK_MS

    d, tl, panel = window.document, window.timeline, window.joint_panel
    d.select(d.skeleton.index["neck"])
    shown = []
    panel.show_joint = lambda j, pose: shown.append(j)
    tl.play()
    tl.timer.stop()
    tl.set_time(0.3)           # playing: the panel's refresh is due in PANEL_PLAYBACK_MS
    assert window.panels.timer.isActive() and shown == []
    tl.pause()
    window.close()
    qtbot.wait(2 * PANEL_PLAYBACK_MS)
    assert shown == []


def test_time_label_keeps_its_width_while_playing_and_fits_the_clips_end(window):
    tl, label = window.timeline, window.timeline.time_label
    widths = set()
    for i in range(20):
        tl.set_time(0.05 * i)
        widths.add(label.width())
    assert len(widths) == 1 and label.minimumWidth() == label.maximumWidth()
    tl.clip_manager.set_duration(400.0)        # a long clip: more digits at its end
    tl.set_time(400.0)
    assert label.width() > widths.pop()
    assert label.fontMetrics().horizontalAdvance(label.text()) <= label.width()


def test_ruler_cursor_repaint_matches_a_whole_repaint(window, qtbot):
    ruler = window.timeline.ruler
    window.timeline.set_time(0.2)
    ruler.repaint()
    window.timeline.set_time(0.7)       # only the time changed: two cursor strips repainted
    ruler.repaint(ruler._cursor_rect(ruler.x_of(0.2)))
    ruler.repaint(ruler._cursor_rect(ruler.x_of(0.7)))
    strips = ruler.grab().toImage()
    ruler._background = None            # forget the cached picture: paint everything
    ruler.repaint()
    whole = ruler.grab().toImage()
    assert strips == whole
    # and the cursor did move: the picture at 0.2 differs
    window.timeline.set_time(0.2)
    ruler.repaint()
    assert ruler.grab().toImage() != whole


def test_scrubbing_with_the_mouse_poses_the_mesh(window, qtbot):
    tl, ruler = window.timeline, window.timeline.ruler
    before = np.array(window.scene.mesh.points)
    gizmo_before = window.gizmos.center(window.document.skeleton.index["head"])
    _mouse(ruler, "press", ruler.x_of(0.1), 5)
    _mouse(ruler, "move", ruler.x_of(0.5), 5)
    _mouse(ruler, "release", ruler.x_of(0.5), 5)
    assert tl.time == pytest.approx(0.5, abs=1 / 30)
    moved = np.abs(np.array(window.scene.mesh.points) - before).max()
    assert moved > 0.05
    # the gizmos follow the pose
    assert np.linalg.norm(window.gizmos.center(window.document.skeleton.index["head"])
                          - gizmo_before) > 0.05


def test_insert_key_with_k_then_undo(window, qtbot):
    tl, doc = window.timeline, window.document
    doc.select("tail")
    tl.set_time(0.25)
    doc.set_joint_euler("tail", [0, 30, 0])
    n = len(doc.undo_stack)
    window.activateWindow()
    qtbot.waitUntil(lambda: QtWidgets.QApplication.activeWindow() is window, timeout=2000)
    qtbot.keyClick(window.plotter, QtCore.Qt.Key_K)
    clip = tl.clip
    assert ("tail", "rotation") in clip.tracks
    assert clip.key_times("tail").tolist() == [0.25]
    assert len(doc.undo_stack) == n + 1
    assert clip.sample(0.25).allclose(doc.pose)
    doc.undo()
    assert ("tail", "rotation") not in clip.tracks


def test_key_all_joints_keys_every_joint(window):
    tl, doc = window.timeline, window.document
    tl.set_time(0.75)
    tl.keys.insert_key(all_joints=True)
    keyed = {j for (j, c) in tl.clip.tracks if c == "rotation" and 0.75 in tl.clip.key_times(j)}
    assert keyed == set(doc.skeleton.names)


def test_drag_a_key_in_the_ruler_moves_it_and_undo_restores(window):
    tl, doc, ruler = window.timeline, window.document, window.timeline.ruler
    doc.select("neck")
    y = _row_y(ruler, 1)                                  # the selected joint's row
    assert ruler.key_at(ruler.x_of(0.5), y) == (0.5, False)
    _mouse(ruler, "press", ruler.x_of(0.5), y)
    _mouse(ruler, "move", ruler.x_of(0.6), y)
    _mouse(ruler, "move", ruler.x_of(0.7), y)
    _mouse(ruler, "release", ruler.x_of(0.7), y)
    np.testing.assert_allclose(tl.clip.key_times("neck"), [0, 0.7, 1], atol=1e-9)
    assert tl.time == pytest.approx(0.7)
    assert doc.undo_stack.undo_label.startswith("Move key")
    doc.undo()
    np.testing.assert_allclose(tl.clip.key_times("neck"), [0, 0.5, 1])


def test_delete_key_and_undo_restore_the_pose(window):
    tl, doc = window.timeline, window.document
    tl.set_time(0.5)
    posed = np.array(window.scene.mesh.points)
    tl.keys.delete_key(all_joints=True)
    np.testing.assert_allclose(tl.clip.key_times("neck"), [0, 1])
    # the neck now stays at rest between two rest keys: the mesh changed
    assert np.abs(np.array(window.scene.mesh.points) - posed).max() > 0.05
    doc.undo()
    np.testing.assert_allclose(np.array(window.scene.mesh.points), posed, atol=1e-5)


def test_copy_paste_keys(window):
    tl, doc = window.timeline, window.document
    doc.select("neck")
    tl.set_time(0.5)
    tl.keys.copy_keys()
    tl.set_time(0.9)
    tl.keys.paste_keys()
    assert tl.clip.sample(0.9).allclose(tl.clip.sample(0.5))
    assert doc.undo_stack.undo_label.startswith("Paste")


def test_auto_key_writes_keys_when_posing(window):
    tl, doc = window.timeline, window.document
    tl.set_auto_key(True)
    tl.set_time(0.2)
    doc.set_joint_euler("tail", [0, 0, 25])
    assert 0.2 in tl.clip.key_times("tail")
    assert tl.clip.sample(0.2).allclose(doc.pose)
    assert "auto-key tail" in doc.undo_stack.undo_label
    steps = len(doc.undo_stack)
    doc.undo()                       # one step takes back the pose edit and its key
    assert len(tl.clip.key_times("tail")) == 0
    assert np.allclose(doc.pose.get_euler("tail", degrees=True), 0, atol=1e-9)
    assert len(doc.undo_stack) == steps - 1
    doc.redo()
    assert 0.2 in tl.clip.key_times("tail")
    assert np.allclose(doc.pose.get_euler("tail", degrees=True), [0, 0, 25], atol=1e-6)
    doc.undo()
    tl.set_auto_key(False)
    doc.set_joint_euler("tail", [0, 0, 10])
    assert len(tl.clip.key_times("tail")) == 0


def test_interpolation_per_track_with_undo(window):
    tl, doc = window.timeline, window.document
    doc.select("neck")
    tl.keys.set_interpolation("catmull_rom", "rotation")
    assert tl.clip.tracks[("neck", "rotation")].interpolation == "catmull_rom"
    assert tl.rot_combo.currentText() == "catmull_rom"
    doc.undo()
    assert tl.clip.tracks[("neck", "rotation")].interpolation == "slerp"


def test_clip_new_rename_duplicate_delete_with_undo(window):
    tl, doc = window.timeline, window.document
    name = tl.clip_manager.new_clip("walk", duration=3.0)
    assert doc.current_clip == name == "walk" and tl.clip_combo.currentText() == "walk"
    assert tl.duration_spin.value() == 3.0
    tl.clip_manager.rename_clip("stride")
    assert "stride" in doc.clips and "walk" not in doc.clips and tl.clip.name == "stride"
    copy = tl.clip_manager.duplicate_clip()
    assert copy == "stride copy" and doc.clips[copy] is not doc.clips["stride"]
    tl.clip_manager.delete_clip()
    assert copy not in doc.clips
    for _ in range(3):
        doc.undo()
    assert set(doc.clips) == {"nod", "walk"} and doc.clips["walk"].name == "walk"
    tl.clip_manager.set_duration(2.0)
    assert doc.clips["walk"].duration == 2.0
    doc.undo()
    assert doc.clips["walk"].duration == 3.0


def test_record_video_from_the_editor(window, tmp_path, qtbot):
    path = tmp_path / "nod.mp4"
    n = window.record_video(path, fps=10, size=(192, 144), progress=True)
    assert n == 10
    frames = np.stack(list(iio.imiter(path)))
    assert frames.shape == (10, 144, 192, 3)
    assert np.abs(frames[5].astype(int) - frames[0].astype(int)).mean() > 2.5  # measured 4.3
    # the editor is still usable: scrubbing still poses the interactive mesh
    before = np.array(window.scene.mesh.points)
    window.timeline.set_time(0.5)
    assert np.abs(np.array(window.scene.mesh.points) - before).max() > 0.05
    assert window.export_video_action.isEnabled()


def test_opening_a_rig_with_other_joints_shows_its_first_clip_pose(window, qtbot):
    # The timeline answers "rig" before the window rebuilds its scene: a "pose" event then
    # skinned the old mesh with the new rig's joint count (an error, and no new rig shown).
    import rigedit

    w = window
    w.files.open_folder(str(rigedit.resolve_rig_path("humanoid")))
    qtbot.waitUntil(lambda: w.job is None, timeout=60000)
    doc = w.document
    assert w.last_error is None, w.last_error
    assert len(doc.skeleton) != len(_rig().skeleton) and doc.current_clip is not None
    shown = np.asarray(w.scene.mesh.points)
    expected = doc.rig.skin(doc.clips[doc.current_clip].sample(doc.time))
    assert shown.shape == expected.shape
    assert np.abs(shown - expected).max() < 1e-4
    assert not np.allclose(expected, doc.rig.vertices, atol=1e-4)   # not the rest pose
