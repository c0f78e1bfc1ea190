"""File > Export compressed and View > Compare compressed in the window (pytest-qt)."""
import numpy as np
import pytest
from PyQt5 import QtCore, QtWidgets

import rigedit
from rigedit.compression import measure_error
from rigedit.editor.events import KeysChanged
from rigedit.render.compare_overlay import COMPARE_LAYER, error_colors
from ui_window_fixture import menu_action

JOB_MS = 30_000


def _wait_job(qtbot, window):
    qtbot.waitUntil(lambda: window.job is None, timeout=JOB_MS)


def _check_only(dialog, names):
    for i in range(dialog.clip_list.count()):
        item = dialog.clip_list.item(i)
        item.setCheckState(QtCore.Qt.Checked if item.text() in names else QtCore.Qt.Unchecked)


def test_the_menus_hold_both_actions(window):
    assert menu_action(window, "File", "Export compressed") is not None
    act = menu_action(window, "View", "Compare compressed")
    assert act.isCheckable() and not act.isChecked()


def test_the_dialog_writes_the_file_and_shows_the_ratio(window, qtbot, tmp_path):
    part = window.export_compressed
    dialog = part.dialog()
    assert dialog.max_error_edit.text() == "0.01" and dialog.shell_edit.text() == "3"
    assert dialog.clips() == list(window.document.clips)   # all by default
    out = tmp_path / "walk.rgc"
    dialog.max_error_edit.setText("0.05")
    dialog.path_edit.setText(str(out))
    assert not dialog.meshopt_box.isEnabled()   # glTF only
    _check_only(dialog, ["walk"])
    dialog.accept()
    assert dialog.result() == QtWidgets.QDialog.Accepted
    part.start(dialog.export)
    _wait_job(qtbot, window)
    report = part.last_report
    assert out.is_file() and report is not None and report.max_error <= 5e-4
    text = part.last_message.text()
    assert f"ratio {report.ratio:.1f}:1" in text and "99th percentile" in text
    assert f"{report.compressed_bytes} bytes" in window.statusBar().currentMessage()
    back = rigedit.load_rig(out)
    rig = window.document.rig
    assert measure_error(rig.skeleton, rig.clips["walk"], back.clips["walk"]).max() <= 5e-4
    assert window.compression.max_error_cm == 0.05   # the comparison's bound now


@pytest.mark.parametrize("field, value, said", [
    ("max_error_edit", "-1", "Max error"), ("max_error_edit", "abc", "Max error"),
    ("max_error_edit", "inf", "Max error"), ("shell_edit", "0", "Shell"),
    ("path_edit", "out.fbx", ".fbx"), ("clips", [], "Clips")])
def test_the_dialog_refuses_bad_values_with_one_message(window, tmp_path, field, value, said):
    dialog = window.export_compressed.dialog()
    dialog.path_edit.setText(str(tmp_path / "out.glb"))
    if field == "clips":
        _check_only(dialog, value)
    elif field == "path_edit":
        dialog.path_edit.setText(str(tmp_path / value))
    else:
        getattr(dialog, field).setText(value)
    dialog.show()
    dialog.accept()
    assert dialog.result() != QtWidgets.QDialog.Accepted and dialog.isVisible()
    assert said in dialog.error_label.text() and dialog.export is None
    assert list(tmp_path.iterdir()) == []
    dialog.close()


def _layers(window):
    rens = window.plotter.render_window.GetRenderers()
    rens.InitTraversal()
    return [rens.GetNextItem().GetLayer() for _ in range(rens.GetNumberOfItems())]


def _turn_on(window, qtbot, bound_cm=0.1):
    window.compression.max_error_cm = bound_cm
    window.compare.set_enabled(True)
    qtbot.waitUntil(lambda: window.compare.overlay is not None and window.job is None,
                    timeout=JOB_MS)
    return window.compare.overlay


def test_the_toggle_draws_every_joint_coloured_by_its_error(window, qtbot):
    doc = window.document
    doc.set_current_clip("walk")
    overlay = _turn_on(window, qtbot)
    preview = window.compare.preview
    bound = preview.max_error
    assert bound == pytest.approx(1e-3) and COMPARE_LAYER in _layers(window)
    seen = []
    for t in np.linspace(0.1, 1.0, 4):
        doc.set_time(t)
        positions, errors = preview.at(t)
        assert len(overlay.positions) == len(doc.skeleton)
        np.testing.assert_allclose(overlay.positions, positions)
        np.testing.assert_array_equal(overlay.colors, error_colors(errors, bound))
        # red minus green grows from green through yellow to red: the worst joint is reddest
        warmth = overlay.colors[:, 0].astype(int) - overlay.colors[:, 1]
        assert warmth[np.argmax(errors)] == warmth.max() > warmth[np.argmin(errors)]
        seen.append(overlay.colors.copy())
    assert any(not np.array_equal(seen[0], c) for c in seen[1:])   # colours follow time
    assert "compressed" in overlay.text.GetInput() and "this frame" in overlay.text.GetInput()
    window.compare.set_enabled(False)
    assert window.compare.overlay is None and COMPARE_LAYER not in _layers(window)
    assert not menu_action(window, "View", "Compare compressed").isChecked()


def test_turning_it_on_without_a_clip_says_so(window):
    window.document.set_current_clip(None)
    window.compare.set_enabled(True)
    assert not window.compare.enabled and window.compare.overlay is None
    assert "no clip" in window.statusBar().currentMessage()
    assert window.job is None


def test_a_clip_edit_while_on_compresses_again(window, qtbot):
    doc = window.document
    doc.set_current_clip("run")
    _turn_on(window, qtbot)
    first = window.compare.preview.entry
    clip = doc.clip
    tracks = dict(clip.tracks)
    key = next(iter(tracks))
    try:
        clip.set_track(*key, tracks[key])   # a new revision
        doc.clip_changed(KeysChanged("run"))   # as a key command announces it
        assert window.job is not None
        assert "compressing it again" in window.statusBar().currentMessage()
        qtbot.waitUntil(lambda: window.job is None and window.compare.preview.entry
                        is not first, timeout=JOB_MS)
        assert not window.compare.preview.stale
        assert window.compare.overlay.line_actor.GetVisibility()
    finally:
        clip.tracks = tracks
        window.compare.set_enabled(False)


def test_a_new_rig_while_on_is_compressed_and_drawn_for_its_skeleton(window, qtbot):
    from builders import cylinder_rig

    quadruped = window.document.rig
    window.document.set_current_clip("walk")
    _turn_on(window, qtbot)
    try:
        window.document.set_rig(cylinder_rig())   # its clip "bend": 3 joints
        qtbot.waitUntil(lambda: window.job is None and window.compare.overlay is not None,
                        timeout=JOB_MS)
        assert len(window.compare.overlay.positions) == 3
        assert window.compare.preview.entry.original.name == "bend"
        assert _layers(window).count(COMPARE_LAYER) == 1   # the old overlay went
    finally:
        window.compare.set_enabled(False)
        window.document.set_rig(quadruped)


@pytest.mark.parametrize("kind", ["walk.rgc", "folder"])
def test_compressed_clips_open_play_and_refuse_edits(window, qtbot, tmp_path, kind):
    from rigedit.editor.compression import ReadOnlyCompressedClip, export_compressed

    original = window.document.rig.clips["walk"]
    out = tmp_path / kind
    export_compressed(window.document, out, 1e-3, clips=["walk"])
    (window.files.open_file if kind.endswith(".rgc") else window.files.open_folder)(str(out))
    _wait_job(qtbot, window)
    doc = window.document
    assert window.last_error is None and isinstance(doc.clip, ReadOnlyCompressedClip)
    assert doc.current_clip == "walk"
    rest = doc.rig.rest_pose().as_array()
    for t in (0.2, 0.7):
        doc.set_time(t)
        shown = doc.pose.as_array()
        assert not np.allclose(shown, rest)
        np.testing.assert_allclose(shown, doc.clip.sample(t).as_array())
        # the compressed pose is the original's within the bound (positions, 1 mm)
        gap = np.linalg.norm(window.scene.joint_positions - doc.rig.joint_matrices(
            original.sample(t, out=doc.rig.rest_pose()))[:, :3, 3], axis=1)
        assert gap.max() <= 1e-3
    keys = doc.clip.key_times()
    # refused with one message (the timeline's error), not an unexpected error
    assert window.timeline.keys.insert_key(all_joints=True) == 0
    assert window.last_error is not None and "cannot be edited" in window.last_error
    np.testing.assert_array_equal(doc.clip.key_times(), keys)
    assert doc.undo_stack.top is None   # nothing was recorded


def test_the_dialog_writes_meshopt_gltf_when_asked(window, qtbot, tmp_path):
    import json
    import struct

    from rigedit.io.gltf_write_compact import meshopt_available

    if not meshopt_available():
        pytest.skip("the meshopt package is not installed")
    part = window.export_compressed
    dialog = part.dialog()
    out = tmp_path / "run.glb"
    dialog.path_edit.setText(str(out))
    assert dialog.meshopt_box.isEnabled()
    dialog.meshopt_box.setChecked(True)
    dialog.max_error_edit.setText("0.1")
    _check_only(dialog, ["run"])
    dialog.accept()
    part.start(dialog.export)
    _wait_job(qtbot, window)
    blob = out.read_bytes()
    length, = struct.unpack("<I", blob[12:16])
    gltf = json.loads(blob[20:20 + length])
    assert "EXT_meshopt_compression" in gltf.get("extensionsRequired", [])
    assert [a.get("name") for a in gltf["animations"]] == ["run"]
    assert part.last_report.max_error <= 1e-3
    dialog.path_edit.setText(str(tmp_path / "run.rgc"))   # not glTF: the box goes off
    assert not dialog.meshopt_box.isEnabled() and not dialog.meshopt_box.isChecked()
