"""The weight brush through real mouse events on the editor's 3D view (under Xvfb): a stroke
paints the selected joint only within the brush radius, rows sum to 1, one undo step restores
the weights exactly, and a Ctrl+click shows a vertex's influences in the info panel."""
import numpy as np
import pytest

import pytestqt  # noqa: F401 - needed: without pytest-qt these fail, never skip

pytestmark = pytest.mark.ui

from ui_window_fixture import demo_window, rig_template, window  # noqa: E402,F401

from rigedit.binding.weight_paint import joint_column  # noqa: E402


def mouse(widget, kind, xy, ctrl=False):
    """A left-button press/move/release at VTK display pixel ``xy`` (y up), sent as a Qt
    mouse event (y down) to the view widget."""
    from PyQt5 import QtCore, QtGui, QtWidgets

    x, y = xy
    qt = QtCore.QPointF(x, widget.height() - 1 - y)
    types = {"press": QtCore.QEvent.MouseButtonPress, "move": QtCore.QEvent.MouseMove,
             "release": QtCore.QEvent.MouseButtonRelease}
    buttons = QtCore.Qt.NoButton if kind == "release" else QtCore.Qt.LeftButton
    mods = QtCore.Qt.ControlModifier if ctrl else QtCore.Qt.NoModifier
    ev = QtGui.QMouseEvent(types[kind], qt, QtCore.Qt.LeftButton, buttons, mods)
    QtWidgets.QApplication.sendEvent(widget, ev)


def display(window, world):
    ren = window.plotter.renderer
    ren.SetWorldPoint(*np.asarray(world, dtype=float), 1.0)
    ren.WorldToDisplay()
    return np.array(ren.GetDisplayPoint()[:2])


def surface_hit(window, xy):
    """Where the ray through display pixel ``xy`` first meets the shown mesh, found with
    VTK's OBB tree (not the brush's picker), and the scene units one pixel spans there."""
    ren = window.plotter.renderer
    ends = []
    for z in (0.0, 1.0):
        ren.SetDisplayPoint(float(xy[0]), float(xy[1]), z)
        ren.DisplayToWorld()
        w = np.array(ren.GetWorldPoint())
        ends.append(w[:3] / w[3])
    mesh = window.scene.mesh
    points, _ = mesh.ray_trace(ends[0], ends[1], first_point=True)
    assert len(points) == 3, f"no surface under pixel {xy}"
    cam = ren.GetActiveCamera()
    depth = float(np.dot(points - np.array(cam.GetPosition()),
                         np.array(cam.GetDirectionOfProjection())))
    height = ren.GetSize()[1]
    per_pixel = 2.0 * depth * np.tan(np.radians(cam.GetViewAngle()) / 2.0) / height
    return np.asarray(points), per_pixel


def start_brush(window, joint, mode="add", radius=25, strength=0.5):
    d = window.document
    d.select(joint)
    window.set_gizmos_visible(False)  # the spheres take presses over them, as they should
    window.weight_brush.action.trigger()
    p = window.weight_brush.panel
    p.set_mode(mode)
    p.radius_box.setValue(radius)
    p.strength_box.setValue(strength)
    assert window.weights_view and window.weight_brush.enabled
    window.plotter.render()


def test_stroke_paints_within_the_radius_only_and_is_one_undo_step(window, qtbot, monkeypatch):
    d = window.document
    j = d.skeleton.index["spine_2"]
    start_brush(window, j, radius=25, strength=0.5)
    centre = display(window, d.skeleton.bind_matrices[j, :3, 3])
    path = [np.round(centre + [6 * k, 2 * k]) for k in range(5)]
    before = d.rig.binding
    before_idx, before_w = before.indices.copy(), before.weights.copy()
    depth = len(d.undo_stack)
    pushed = []
    real = d.set_weights
    monkeypatch.setattr(d, "set_weights", lambda i, w, label="": (
        pushed.append((i.copy(), w.copy(), label)), real(i, w, label=label)))

    mouse(window.plotter, "press", path[0])
    for xy in path[1:]:
        mouse(window.plotter, "move", xy)
    # colours follow the stroke before it ends
    shown = np.asarray(window.scene.mesh.point_data["weight"])
    assert not np.allclose(shown, joint_column(before_idx, before_w, j), atol=1e-6)
    assert len(d.undo_stack) == depth
    mouse(window.plotter, "release", path[-1])

    assert len(d.undo_stack) == depth + 1 and d.undo_stack.undo_label == "Paint spine_2"
    (idx, w, _), = pushed
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-9)  # rows as painted, unscaled
    after = d.rig.binding.dense()
    changed = np.flatnonzero(np.abs(after - before.dense()).max(axis=1) > 1e-9)
    assert len(changed) > 20
    # every changed vertex lies within the brush radius of one of the dab points
    shown_pts = np.asarray(window.scene.mesh.points, dtype=float)
    near = np.zeros(len(shown_pts), dtype=bool)
    for xy in path:
        hit, per_pixel = surface_hit(window, xy)
        near |= np.linalg.norm(shown_pts - hit, axis=1) < 25 * per_pixel * 1.03
    assert near[changed].all()
    assert (~near).sum() > 0.9 * len(shown_pts)  # the brush is local
    assert after[changed, j].mean() > before.dense()[changed, j].mean()  # add raised it

    d.undo()
    assert d.rig.binding is before
    np.testing.assert_array_equal(d.rig.binding.indices, before_idx)
    np.testing.assert_array_equal(d.rig.binding.weights, before_w)
    np.testing.assert_allclose(np.asarray(window.scene.mesh.point_data["weight"]),
                               joint_column(before_idx, before_w, j), atol=1e-6)


def test_locked_joint_keeps_its_weights_and_mirror_paints_the_other_side(window, qtbot):
    d = window.document
    sk = d.skeleton
    j = sk.index["fore_upper_L"]
    start_brush(window, sk.index["scapula_L"], radius=40, strength=1.0)
    window.weight_brush.panel.lock_box.setChecked(True)  # lock scapula_L
    assert window.weight_brush.locked == {sk.index["scapula_L"]}
    d.select(j)
    window.weight_brush.panel.mirror_box.setChecked(True)
    before = d.rig.binding.dense()
    xy = np.round(display(window, sk.bind_matrices[j, :3, 3] * 0.5
                          + sk.bind_matrices[sk.index["fore_lower_L"], :3, 3] * 0.5))
    mouse(window.plotter, "press", xy)
    mouse(window.plotter, "move", xy + [3, 0])
    mouse(window.plotter, "release", xy + [3, 0])
    after = d.rig.binding.dense()
    # (to the last bit before SkinBinding divides each row by its sum, ~1e-16 off 1)
    np.testing.assert_allclose(after[:, sk.index["scapula_L"]],
                               before[:, sk.index["scapula_L"]], rtol=0, atol=1e-14)
    left = after[:, j] - before[:, j]
    right = after[:, sk.index["fore_upper_R"]] - before[:, sk.index["fore_upper_R"]]
    assert left.max() > 0.05 and right.max() > 0.05  # both sides painted
    verts = d.rig.vertices
    side = d._side_axis()
    centre = 0.5 * (verts[:, side].min() + verts[:, side].max())
    # each side's joint changed on its own side of the body only
    assert np.sign(np.median(verts[left > 1e-9, side] - centre)) == \
        -np.sign(np.median(verts[right > 1e-9, side] - centre))


def test_ctrl_click_shows_the_vertex_influences_and_paints_nothing(window, qtbot):
    d = window.document
    j = d.skeleton.index["neck_2"]
    start_brush(window, j)
    xy = np.round(display(window, d.skeleton.bind_matrices[j, :3, 3]))
    depth = len(d.undo_stack)
    mouse(window.plotter, "press", xy, ctrl=True)
    mouse(window.plotter, "release", xy, ctrl=True)
    assert len(d.undo_stack) == depth  # nothing painted
    hit, _ = surface_hit(window, xy)
    pts = np.asarray(window.scene.mesh.points, dtype=float)
    v = int(np.argmin(np.linalg.norm(pts - hit, axis=1)))
    text = window.info_panel.labels["Vertex"].text()
    b = d.rig.binding
    assert text.splitlines()[0] == f"#{v:,}"
    for k in range(b.indices.shape[1]):
        if b.weights[v, k] > 0:
            assert f"{d.skeleton.names[b.indices[v, k]]}: {b.weights[v, k]:.3f}" in text
    assert len(text.splitlines()) == 1 + int((b.weights[v] > 0).sum())


def test_brush_off_leaves_the_camera_to_the_mouse(demo_window, qtbot):
    w = demo_window
    d = w.document
    d.select(3)
    w.set_gizmos_visible(False)
    w.set_weights_view(True)  # the view alone is not the brush
    cam = w.plotter.camera
    before = np.array(cam.position)
    xy = np.round(display(w, d.skeleton.bind_matrices[3, :3, 3]))
    depth = len(d.undo_stack)
    mouse(w.plotter, "press", xy)
    for k in range(1, 6):
        mouse(w.plotter, "move", xy + [10 * k, 0])
    mouse(w.plotter, "release", xy + [50, 0])
    assert len(d.undo_stack) == depth
    assert not np.allclose(np.array(cam.position), before)  # the camera turned instead


def test_painted_weights_save_into_the_rig_folder_and_export_to_gltf(window, qtbot, tmp_path):
    import rigedit
    from rigedit.io.save import save_rig

    d = window.document
    j = d.skeleton.index["spine_3"]
    start_brush(window, j, mode="set", radius=30, strength=1.0)
    before = d.rig.binding.dense()
    xy = np.round(display(window, d.skeleton.bind_matrices[j, :3, 3]))
    mouse(window.plotter, "press", xy)
    mouse(window.plotter, "release", xy)
    painted = d.rig.binding.dense()
    changed = np.abs(painted - before).max(axis=1) > 1e-3
    assert changed.sum() > 10

    assert window.files.save_to(tmp_path / "rig")
    with np.load(tmp_path / "rig" / "weights.npz") as z:
        assert z["weights"].dtype == np.float32
    saved = rigedit.load_rig(tmp_path / "rig")
    np.testing.assert_allclose(saved.binding.dense(), painted, atol=1e-6)

    save_rig(d.rig, tmp_path / "painted.glb")
    back = rigedit.load_rig(tmp_path / "painted.glb")
    assert len(back.vertices) == len(d.rig.vertices)
    cols = [back.skeleton.index[n] for n in d.skeleton.names]
    np.testing.assert_allclose(back.binding.dense()[:, cols], painted, atol=1e-6)


def test_plain_click_in_the_weights_view_shows_a_vertex_when_the_brush_is_off(demo_window,
                                                                              qtbot):
    w = demo_window
    d = w.document
    w.set_gizmos_visible(False)
    w.set_weights_view(True)
    assert not w.weight_brush.enabled
    xy = np.round(display(w, d.skeleton.bind_matrices[4, :3, 3]))
    depth = len(d.undo_stack)
    mouse(w.plotter, "press", xy)
    mouse(w.plotter, "release", xy)
    assert len(d.undo_stack) == depth
    hit, _ = surface_hit(w, xy)
    pts = np.asarray(w.scene.mesh.points, dtype=float)
    v = int(np.argmin(np.linalg.norm(pts - hit, axis=1)))
    assert w.info_panel.labels["Vertex"].text().splitlines()[0] == f"#{v:,}"
    # a drag is a camera turn, not a click: the row keeps the vertex shown before
    w.info_panel.show_vertex(None, [])
    mouse(w.plotter, "press", xy)
    for k in range(1, 4):
        mouse(w.plotter, "move", xy + [8 * k, 0])
    mouse(w.plotter, "release", xy + [24, 0])
    assert w.info_panel.labels["Vertex"].text() == "-"


def test_brush_circle_follows_the_mouse_over_the_mesh_and_hides_when_it_leaves(demo_window,
                                                                               qtbot):
    from PyQt5 import QtCore, QtWidgets

    w = demo_window
    d = w.document
    start_brush(w, 4, radius=30)
    circle = w.weight_brush.circle.actor
    xy = np.round(display(w, d.skeleton.bind_matrices[4, :3, 3]))
    qt = QtCore.QPoint(int(xy[0]), int(w.plotter.height() - 1 - xy[1]))
    qtbot.mouseMove(w.plotter, qt)  # no button held: hovering
    assert circle.GetVisibility()
    pts = np.array([w.weight_brush.circle.polydata.GetPoint(k) for k in range(64)])[:, :2]
    np.testing.assert_allclose(pts.mean(axis=0), xy, atol=0.5)
    np.testing.assert_allclose(np.linalg.norm(pts - xy, axis=1), 30, atol=1e-4)  # float32
    assert len(d.undo_stack) == 0  # hovering paints nothing
    QtWidgets.QApplication.sendEvent(w.plotter, QtCore.QEvent(QtCore.QEvent.Leave))
    assert not circle.GetVisibility()
