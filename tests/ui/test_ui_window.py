"""The editor window under Xvfb: gizmos, drags (widget events and real mouse events), panel
edits, undo, view modes, bind mode, bad files, screenshot."""

import numpy as np
import pytest

pytestmark = [pytest.mark.ui, pytest.mark.filterwarnings("error::RuntimeWarning")]

from ui_window_fixture import limb_joint as _limb_joint  # noqa: E402


def _moved_and_still(rig, chain_top):
    """Masks of vertices bound (at all) to the moved subtree and bound only outside it."""
    sub = np.zeros(len(rig.skeleton), dtype=bool)
    sub[rig.skeleton.subtree(chain_top)] = True
    b = rig.binding
    touched = np.any(sub[b.indices] & (b.weights > 1e-6), axis=1)
    main = sub[b.indices[:, 0]] & (b.weights[:, 0] > 0.9)
    return main, ~touched


def test_window_draws_one_sphere_per_joint_as_one_actor(window):
    n = len(window.document.skeleton)
    assert len(window.gizmos) == n
    actor = window.gizmos.glyphs.actor
    assert actor.GetVisibility() and window.overlay.HasViewProp(actor)
    assert actor.GetMapper().GetInput().GetNumberOfPoints() == n
    heads = window.document.rig.joint_matrices(window.document.pose)[:, :3, 3]
    np.testing.assert_allclose(window.gizmos.positions, heads, atol=1e-6)
    assert window.info_panel.labels["Joints"].text() == str(n)




def test_sphere_interaction_moves_subtree_vertices_only(window):
    doc = window.document
    rig, sk = doc.rig, doc.skeleton
    j = _limb_joint(sk)
    window.chain_length = 1
    top = sk.parents[j]
    before = window.scene.mesh.points.copy()
    head = window.gizmos.center(j)
    window.gizmos.drag(j, head + np.array([0.0, 0.0, 0.3]) * rig.height())
    after = window.scene.mesh.points
    moving, still = _moved_and_still(rig, top)
    assert moving.sum() > 10 and still.sum() > 10
    shift = np.linalg.norm(after - before, axis=1)
    assert np.median(shift[moving]) > 0.1 * rig.height()  # measured 0.163
    assert shift[still].max() < 1e-5
    assert len(doc.undo_stack) == 1 and doc.selection == j
    # the sphere snapped onto the joint, which stays at its bone length from the parent
    model = rig.joint_matrices(doc.pose)
    np.testing.assert_allclose(window.gizmos.center(j), model[j, :3, 3], atol=1e-5)
    rest = sk.bind_matrices
    np.testing.assert_allclose(np.linalg.norm(model[j, :3, 3] - model[top, :3, 3]),
                               np.linalg.norm(rest[j, :3, 3] - rest[top, :3, 3]), rtol=1e-6)


def test_real_mouse_drag_over_sphere(window, qtbot):
    doc = window.document
    rig, sk = doc.rig, doc.skeleton
    j = _limb_joint(sk)
    window.view("side")
    window.plotter.render()
    iren = window.plotter.iren.interactor
    x, y = window.gizmos.display_position(j)
    before = window.scene.mesh.points.copy()
    rest = doc.pose_snapshot()
    iren.SetEventInformation(int(round(x)), int(round(y)))
    iren.InvokeEvent("LeftButtonPressEvent")
    assert window.gizmos.active == j  # the press picked this joint's sphere
    for step in range(1, 6):
        iren.SetEventInformation(int(round(x)) + 8 * step, int(round(y)) + 6 * step)
        iren.InvokeEvent("MouseMoveEvent")
    mid = window.scene.mesh.points.copy()
    assert np.abs(mid - before).max() > 1e-3 * rig.height()  # moved during the drag
    iren.InvokeEvent("LeftButtonReleaseEvent")
    assert window.gizmos.active is None
    assert len(doc.undo_stack) == 1
    assert not np.array_equal(doc.pose_snapshot(), rest)
    model = rig.joint_matrices(doc.pose)
    np.testing.assert_allclose(window.gizmos.center(j), model[j, :3, 3], atol=1e-5)
    doc.undo()
    np.testing.assert_array_equal(doc.pose_snapshot(), rest)
    np.testing.assert_allclose(window.scene.mesh.points, before, atol=1e-6)


def test_axis_constraint_keeps_drag_on_axis(window):
    doc = window.document
    sk = doc.skeleton
    root = 0
    window.set_axis(1)  # Y
    start = window.gizmos.center(root)
    window.gizmos.drag(root, start + np.array([0.4, 0.25, -0.3]))
    moved = doc.pose.translation[root] - sk.rest_translation[root]
    np.testing.assert_allclose(moved, [0.0, 0.25, 0.0], atol=1e-9)


def test_root_drag_moves_whole_character(window):
    doc = window.document
    before = window.scene.mesh.points.copy()
    start = window.gizmos.center(0)
    window.gizmos.drag(0, start + [0.1, 0.0, 0.2])
    np.testing.assert_allclose(window.scene.mesh.points - before,
                               np.tile([0.1, 0.0, 0.2], (len(before), 1)), atol=1e-4)
    assert doc.undo_stack.undo_label.startswith("Drag")


def test_panel_edits_rotate_joint_and_undo_redo_exactly(window):
    doc = window.document
    j = _limb_joint(doc.skeleton)
    doc.select(j)
    panel = window.joint_panel
    rest = doc.pose_snapshot()
    before = window.scene.mesh.points.copy()
    panel.angle_boxes[0].setValue(35.0)
    np.testing.assert_allclose(doc.pose.get_euler(j, degrees=True), [35, 0, 0], atol=1e-9)
    assert np.abs(window.scene.mesh.points - before).max() > 0
    panel.angle_boxes[2].setValue(-20.0)
    np.testing.assert_allclose(doc.pose.get_euler(j, degrees=True), [35, 0, -20], atol=1e-9)
    edited = doc.pose_snapshot()
    window.undo_action.trigger()
    window.undo_action.trigger()
    np.testing.assert_array_equal(doc.pose_snapshot(), rest)
    assert panel.angle_boxes[0].value() == 0.0  # the panel follows the document
    np.testing.assert_allclose(window.scene.mesh.points, before, atol=1e-6)
    window.redo_action.trigger()
    window.redo_action.trigger()
    np.testing.assert_array_equal(doc.pose_snapshot(), edited)
    window.joint_panel.reset_joint_button.click()
    np.testing.assert_array_equal(doc.pose_snapshot(), rest)


def test_tree_and_sphere_select_the_same_joint(window):
    doc = window.document
    j = _limb_joint(doc.skeleton)
    item = window.joint_panel._items[j]
    window.joint_panel.tree.setCurrentItem(item)
    assert doc.selection == j
    assert window.gizmos.selected == j
    sel = window.gizmos.glyphs.color_of(j)
    other = window.gizmos.glyphs.color_of(_limb_joint(doc.skeleton, "fore_cannon_R"))
    assert not np.allclose(sel, other)
    window.gizmos.start_drag(0)
    window.gizmos.end_drag()
    assert doc.selection == 0
    assert window.joint_panel.tree.selectedItems()[0] is window.joint_panel._items[0]


def test_view_modes_toggle(window):
    prop = window.scene.mesh_actor.GetProperty()
    window.set_display_mode("wireframe")
    assert prop.GetRepresentation() == 1  # VTK_WIREFRAME
    window.set_display_mode("translucent")
    assert prop.GetRepresentation() == 2 and prop.GetOpacity() < 1 and prop.GetEdgeVisibility()
    window.set_display_mode("solid")
    assert prop.GetOpacity() == 1 and not prop.GetEdgeVisibility()
    window.set_skeleton_visible(False)
    assert not window.scene.bone_actor.GetVisibility()
    window.set_gizmos_visible(False)
    assert not window.gizmos.glyphs.actor.GetVisibility()
    x, y = window.gizmos.display_position(0)
    assert window.gizmos.pick(x, y) is None  # hidden spheres are not picked
    window.set_gizmos_visible(True)
    assert window.gizmos.glyphs.actor.GetVisibility()
    assert window.gizmos.pick(x, y) is not None
    j = _limb_joint(window.document.skeleton)
    window.document.select(j)
    window.set_weights_view(True)
    mapper = window.scene.mesh_actor.GetMapper()
    assert mapper.GetScalarVisibility()
    expected = window.document.rig.weights[:, j].toarray().ravel()
    np.testing.assert_allclose(window.scene.mesh.point_data["weight"], expected, atol=1e-6)
    window.set_weights_view(False)
    assert not mapper.GetScalarVisibility()


def test_mirror_button(window):
    doc = window.document
    sk = doc.skeleton
    names = [n for n in sk.names if n.endswith("_L") and n[:-2] + "_R" in sk.index]
    assert names
    left = sk.index[names[0]]
    right = sk.index[names[0][:-2] + "_R"]
    doc.set_joint_euler(left, [0, 0, 25])
    window.joint_panel.mirror_lr_button.click()
    assert not np.allclose(doc.pose.rotation[right], sk.rest_rotation[right])
    window.undo_action.trigger()
    np.testing.assert_array_equal(doc.pose.rotation[right], sk.rest_rotation[right])


def test_edit_mode_drag_rebinds_in_worker_and_undoes(window, qtbot):
    doc = window.document
    sk0 = doc.skeleton
    binding0 = doc.rig.binding
    j = _limb_joint(sk0)
    window.set_mode("edit")
    start = window.gizmos.center(j)
    target = start + np.array([0.0, 0.05, 0.0]) * doc.rig.height()
    window.gizmos.drag(j, target)
    assert window.job is not None  # re-binding runs off the UI thread
    assert window.progress.isVisible() and window.cancel_button.isVisible()
    qtbot.waitUntil(lambda: window.job is None, timeout=30000)
    assert doc.skeleton is not sk0
    np.testing.assert_allclose(doc.skeleton.bind_matrices[j, :3, 3], target, atol=1e-9)
    assert doc.rig.binding is not binding0
    window.undo_action.trigger()
    assert doc.skeleton is sk0 and doc.rig.binding is binding0
    window.set_mode("pose")


def test_rebind_can_be_cancelled(window, qtbot):
    doc = window.document
    sk0 = doc.skeleton
    done = []
    job = window.run_job("slow", lambda report: [report(i / 1000) or __import__("time").sleep(0.01)
                                                 for i in range(1000)], done.append)
    assert job is not None
    window.cancel_button.click()
    qtbot.waitUntil(lambda: window.job is None, timeout=10000)
    assert done == [] and doc.skeleton is sk0
    assert "cancelled" in window.statusBar().currentMessage()


def test_broken_rig_folder_keeps_current_rig(window, qtbot, tmp_path):
    (tmp_path / "mesh.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (tmp_path / "skeleton.json").write_text("{not json")
    rig = window.document.rig
    window.files.open_folder(str(tmp_path))
    qtbot.waitUntil(lambda: window.job is None, timeout=10000)
    assert window.document.rig is rig
    assert "skeleton.json" in window.last_error
    assert "skeleton.json" in window.statusBar().currentMessage()
    window._last_dialog.close()


def test_open_and_save_round_trip(window, qtbot, tmp_path):
    from rigedit.ui.fallback import demo_rig

    from rigedit.io import save_rig_folder

    save_rig_folder(tmp_path / "demo", demo_rig())
    window.files.open_folder(str(tmp_path / "demo"))
    qtbot.waitUntil(lambda: window.job is None, timeout=10000)
    assert window.last_error is None
    assert window.document.rig.name == "demo creature"
    assert len(window.gizmos) == len(window.document.skeleton) == 19
    assert window.files.export_pose(str(tmp_path / "pose.json"))
    assert window.files.export_skeleton(str(tmp_path / "sk.json"))
    assert window.files.save_weights(str(tmp_path / "w.npz"))
    assert window.files.load_weights(str(tmp_path / "w.npz"))
    assert not window.files.load_weights(str(tmp_path / "pose.json"))
    assert "pose.json" in window.last_error
    window._last_dialog.close()


def test_screenshot_shows_the_model(window, tmp_path):
    from PyQt5 import QtGui

    path = tmp_path / "shot.png"
    window.screenshot(path)
    img = QtGui.QImage(str(path))
    assert img.width() >= window.width() * 0.9
    window.scene.mesh_actor.SetVisibility(False)
    empty = window.screenshot()
    window.scene.mesh_actor.SetVisibility(True)

    def arr(q):
        q = q.convertToFormat(QtGui.QImage.Format_RGB888)
        ptr = q.constBits()
        ptr.setsize(q.byteCount())
        return np.frombuffer(ptr, np.uint8).reshape(q.height(), q.bytesPerLine())[:, :q.width() * 3]\
            .reshape(q.height(), q.width(), 3).astype(int)

    a, b = arr(img), arr(empty)
    assert a.std() > 10  # not blank
    diff = np.abs(a - b).sum(axis=2) > 30
    ys, xs = np.nonzero(diff)
    # the mesh covers a part of the 3D view (measured 5.5% on the quadruped, 1100x750 window)
    view = window.plotter.geometry()
    assert 0.04 < diff.sum() / (view.width() * view.height()) < 0.08
    # ... within the 3D view, around its middle
    cx, cy = xs.mean(), ys.mean()
    assert view.left() < cx < view.right() and view.top() < cy < view.bottom() + 60
