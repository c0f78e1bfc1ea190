"""The File menu through its actions on a window under Xvfb (only the modal file dialogs are
replaced): Save and Save As write a folder that loads back equal to the document, Open mesh +
skeleton builds a rig with computed weights, Export video records what the dialog asks."""
import imageio.v3 as iio
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

pytestmark = [pytest.mark.ui, pytest.mark.filterwarnings("error::RuntimeWarning")]

from PyQt5 import QtCore, QtWidgets  # noqa: E402

from rigedit.animation import Clip, Track  # noqa: E402
from rigedit.io.rig_folder import load_rig_folder  # noqa: E402
from rigedit.binding.weights import compute_weights  # noqa: E402

from ui_window_fixture import answer_file_dialog, editor_window, menu_action  # noqa: E402


def _no_dialogs(monkeypatch):
    for name in ("getExistingDirectory", "getOpenFileName", "getSaveFileName"):
        answer_file_dialog(monkeypatch, name)


def assert_same_rig(back, rig):
    """Everything a rig folder stores: mesh, skeleton, weights, clips, name and up axis."""
    assert back.name == rig.name and back.up == rig.up
    np.testing.assert_allclose(back.vertices, rig.vertices, rtol=0, atol=6e-7)  # OBJ: 6 decimals
    np.testing.assert_array_equal(back.faces, rig.faces)
    a, b = back.skeleton, rig.skeleton
    assert a.names == b.names
    np.testing.assert_array_equal(a.parents, b.parents)
    np.testing.assert_array_equal(a.deform, b.deform)
    np.testing.assert_allclose(a.bind_matrices, b.bind_matrices, atol=1e-9)
    np.testing.assert_allclose(a.rest_translation, b.rest_translation, atol=1e-9)
    np.testing.assert_allclose(a.rest_rotation, b.rest_rotation, atol=1e-9)
    np.testing.assert_array_equal(back.binding.indices, rig.binding.indices)
    # weights.npz stores float32 (rows renormalised on load)
    np.testing.assert_allclose(back.binding.weights, rig.binding.weights, rtol=0, atol=1.2e-7)
    assert set(back.clips) == set(rig.clips)
    for name, clip in rig.clips.items():
        other = back.clips[name]
        assert other.duration == pytest.approx(clip.duration) and other.loop == clip.loop
        assert set(other.tracks) == set(clip.tracks), name
        for key, track in clip.tracks.items():
            got = other.tracks[key]
            assert got.interpolation == track.interpolation, (name, key)
            np.testing.assert_allclose(got.times, track.times, atol=1e-9)
            np.testing.assert_allclose(got.values, track.values, atol=1e-9)


def test_save_as_then_save_from_the_menu(window, qtbot, tmp_path, monkeypatch):
    doc = window.document
    rig = doc.rig
    assert len(rig.clips) >= 3
    asked = answer_file_dialog(monkeypatch, "getExistingDirectory", str(tmp_path / "elk"))
    (tmp_path / "elk").mkdir()
    menu_action(window, "File", "Save rig as").trigger()
    assert len(asked) == 1 and window.last_error is None
    assert str(tmp_path / "elk") in window.statusBar().currentMessage()
    assert_same_rig(load_rig_folder(tmp_path / "elk"), rig)
    # a weights edit, then File > Save: written to the same folder without asking again
    _no_dialogs(monkeypatch)
    one = np.zeros_like(rig.binding.weights)
    one[:, 0] = 1.0
    idx = np.full_like(rig.binding.indices, int(np.flatnonzero(rig.skeleton.deform)[-1]))
    doc.set_weights(idx, one)
    menu_action(window, "File", "Save rig").trigger()
    assert window.last_error is None
    back = load_rig_folder(tmp_path / "elk")
    assert_same_rig(back, rig)
    assert np.all(back.binding.indices[:, 0] == idx[:, 0])


def _small_rig():
    """The demo creature with two clips (code-built: fast to save and load)."""
    from rigedit.ui.fallback import demo_rig

    rig = demo_rig()
    sk = rig.skeleton
    q = [Rotation.from_euler("x", a, degrees=True).as_quat() for a in (0, 40, 0)]
    rig.clips["nod"] = Clip("nod", sk, {("neck", "rotation"): Track("rotation", [0, .5, 1], q)})
    rig.clips["wag"] = Clip("wag", sk, {("tail", "rotation"): Track(
        "rotation", [0, .25, .5], [Rotation.from_euler("y", a, degrees=True).as_quat()
                                   for a in (-30, 30, -30)], interpolation="catmull_rom"),
        ("tail", "scale"): Track("scale", [0, .5], [[1, 1, 1], [1.2, 1, 1]])}, duration=0.5)
    return rig


def test_open_edit_save_and_save_as_a_rig_folder(qtbot, tmp_path, monkeypatch):
    from rigedit.io import save_rig_folder

    save_rig_folder(tmp_path / "a", _small_rig())
    with editor_window(qtbot, _small_rig()) as window:
        doc = window.document
        answer_file_dialog(monkeypatch, "getExistingDirectory", str(tmp_path / "a"))
        menu_action(window, "File", "Open rig folder").trigger()
        qtbot.waitUntil(lambda: window.job is None, timeout=10000)
        assert window.last_error is None and doc.rig.path is not None
        opened = doc.rig
        # edits of what a rig folder keeps: a clip renamed, one deleted, a key, a rest move
        tl = window.timeline
        doc.set_current_clip("nod")
        tl.clip_manager.rename_clip("bow")
        doc.set_current_clip("wag")
        tl.clip_manager.delete_clip()
        doc.set_current_clip("bow")
        tl.set_time(0.25)
        doc.select("head")
        doc.set_joint_euler("head", [0, 20, 0])
        tl.keys.insert_key()                             # K: keys the selected joint
        assert set(doc.clips) == {"bow"}
        _no_dialogs(monkeypatch)
        menu_action(window, "File", "Save rig").trigger()
        assert window.last_error is None
        back = load_rig_folder(tmp_path / "a")
        assert_same_rig(back, opened)
        assert set(back.clips) == {"bow"}          # the deleted and the old name are gone
        assert ("head", "rotation") in back.clips["bow"].tracks
        # Save As to a new folder: both load equal; later saves go to the new one
        (tmp_path / "b").mkdir()
        answer_file_dialog(monkeypatch, "getExistingDirectory", str(tmp_path / "b"))
        menu_action(window, "File", "Save rig as").trigger()
        assert_same_rig(load_rig_folder(tmp_path / "b"), opened)
        _no_dialogs(monkeypatch)
        tl.clip_manager.set_duration(2.0)
        menu_action(window, "File", "Save rig").trigger()
        assert load_rig_folder(tmp_path / "b").clips["bow"].duration == 2.0
        assert load_rig_folder(tmp_path / "a").clips["bow"].duration == 1.0


def test_open_mesh_and_skeleton_from_the_menu(demo_window, qtbot, tmp_path, monkeypatch):
    from rigedit.io.mesh import save_obj
    from rigedit.io.skeleton_json import save_skeleton

    window = demo_window
    source = _small_rig()
    save_obj(tmp_path / "body.obj", source.vertices, source.faces)
    save_skeleton(tmp_path / "bones.json", source.skeleton, up=source.up)
    asked = answer_file_dialog(monkeypatch, "getOpenFileName", str(tmp_path / "body.obj"),
                    str(tmp_path / "bones.json"))
    old = window.document.rig
    window.document.set_joint_euler("neck", [10, 0, 0])
    menu_action(window, "File", "Open mesh + skeleton").trigger()
    assert len(asked) == 2
    qtbot.waitUntil(lambda: window.job is None, timeout=30000)
    assert window.last_error is None
    rig = window.document.rig
    assert rig is not old and rig.name == "body" and rig.clips == {}
    np.testing.assert_allclose(rig.vertices, source.vertices, atol=6e-7)
    np.testing.assert_array_equal(rig.faces, source.faces)
    assert rig.skeleton.names == source.skeleton.names
    np.testing.assert_allclose(rig.skeleton.bind_matrices, source.skeleton.bind_matrices,
                               atol=1e-9)
    # the editor's method for this mesh, as the rig records it (heat for a mesh with faces
    # where that is the default, idw before)
    method = getattr(rig, "weights_method", "idw")
    idx, w = compute_weights(rig.vertices, rig.skeleton, method, faces=rig.faces)
    np.testing.assert_array_equal(rig.binding.indices, idx)
    np.testing.assert_allclose(rig.binding.weights, w, rtol=0, atol=1e-14)
    # the view shows the new rig at rest, history starts afresh
    assert len(window.gizmos) == len(rig.skeleton)
    np.testing.assert_allclose(window.scene.mesh.points, rig.vertices, atol=1e-5)
    assert len(window.document.undo_stack) == 0
    assert window.info_panel.labels["Vertices"].text() == f"{len(rig.vertices):,}"
    # a broken skeleton file: one message naming it, the rig stays
    (tmp_path / "bad.json").write_text('{"joints": [{"name": "a", "head": "up"}]}')
    answer_file_dialog(monkeypatch, "getOpenFileName", str(tmp_path / "body.obj"),
                       str(tmp_path / "bad.json"))
    menu_action(window, "File", "Open mesh + skeleton").trigger()
    qtbot.waitUntil(lambda: window.job is None, timeout=30000)
    assert window.document.rig is rig
    assert "bad.json" in window.last_error
    window._last_dialog.close()


def _export_video(window, qtbot, fields, browse=False, on_record=None):
    """File > Export video: fill the dialog's ``fields`` ({name of the widget: text typed}),
    optionally through Browse, press Record; ``on_record`` is called (from the event loop)
    once recording has begun. Returns the path the dialog showed."""
    from rigedit.ui.record_dialog import RecordDialog

    seen = {}

    def button(dialog, start):
        return next(b for b in dialog.findChildren(QtWidgets.QPushButton)
                    if b.text().startswith(start))

    def fill():
        dialog = QtWidgets.QApplication.activeModalWidget()
        try:
            assert isinstance(dialog, RecordDialog), dialog
            if browse:
                button(dialog, "Browse").click()
            for name, text in fields.items():
                box = getattr(dialog, name)
                box.selectAll()
                qtbot.keyClicks(box, text)
                qtbot.keyClick(box, QtCore.Qt.Key_Tab)
            seen["path"] = dialog.path_edit.text()
            if on_record is not None:
                QtCore.QTimer.singleShot(0, on_record)
            button(dialog, "Record").click()
        except BaseException as exc:  # never leave the modal dialog open
            seen["error"] = exc
            dialog.reject()

    QtCore.QTimer.singleShot(0, fill)
    menu_action(window, "File", "Export video").trigger()
    assert "error" not in seen, seen.get("error")
    return seen["path"]


def test_export_video_dialog_records_what_it_was_asked(window, qtbot, tmp_path, monkeypatch):
    doc = window.document
    assert doc.clips[doc.current_clip].duration >= 1.0
    out = tmp_path / "clip.gif"
    answer_file_dialog(monkeypatch, "getSaveFileName", str(out))
    path = _export_video(window, qtbot, {"width_spin": "160", "height_spin": "120",
                                         "fps_spin": "10", "start_spin": "0.2",
                                         "end_spin": "0.8"}, browse=True)
    assert path == str(out)
    assert window.last_error is None
    frames = iio.imread(out, index=None)
    assert frames.shape[:3] == (6, 120, 160)       # 0.2 s to 0.8 s at 10 frames/s
    # it moves (measured 2.1: the head nods in a small part of the frame)
    assert np.abs(frames[-1].astype(int) - frames[0].astype(int)).mean() > 1.2
    assert "Recorded 6 frames" in window.statusBar().currentMessage()


def test_export_video_cancel_and_bad_folder(window, qtbot, tmp_path):
    out = tmp_path / "clip.mp4"
    out.write_bytes(b"an older video")
    pressed = []

    def cancel():
        progress = [d for d in window.findChildren(QtWidgets.QProgressDialog) if d.isVisible()]
        assert len(progress) == 1, progress
        button = next(b for b in progress[0].findChildren(QtWidgets.QPushButton)
                      if b.text() == "Cancel")
        button.click()
        pressed.append(progress[0].labelText())

    _export_video(window, qtbot, {"path_edit": str(out), "width_spin": "96",
                                  "height_spin": "64", "fps_spin": "30"}, on_record=cancel)
    assert pressed and "clip.mp4" in pressed[0]
    assert out.read_bytes() == b"an older video"          # a cancel keeps the existing file
    assert sorted(p.name for p in tmp_path.iterdir()) == ["clip.mp4"]  # and no temporary
    assert "cancelled" in window.statusBar().currentMessage()
    assert window.last_error is None
    missing = tmp_path / "no such folder" / "clip.gif"
    _export_video(window, qtbot, {"path_edit": str(missing), "width_spin": "96",
                                  "height_spin": "64"})
    assert "no such folder" in window.last_error
    assert not missing.parent.exists()
    window._last_dialog.close()
