"""The selected joint's X/Y/Z arrows are drag handles (real interactor events under Xvfb):
a drag on an arrow moves the joint along that world axis only, through the same code as a
sphere drag (edit mode: rest position; pose mode: root translation), as one undo step."""

import numpy as np
import pytest

pytestmark = [pytest.mark.ui, pytest.mark.filterwarnings("error::RuntimeWarning")]

from ui_window_fixture import limb_joint as _limb_joint  # noqa: E402


def _display(window, world):
    """Display (pixel) coordinates of a world point, as VTK's events use them."""
    ren = window.overlay
    ren.SetWorldPoint(*np.asarray(world, dtype=float), 1.0)
    ren.WorldToDisplay()
    return np.array(ren.GetDisplayPoint()[:2])


def _press_arrow(window, axis, fraction=0.85):
    """Press the left button on arrow ``axis`` of the selected joint; returns the pixel and
    the world point grabbed."""
    window.plotter.render()
    a = window.axes
    grab = a.position() + np.eye(3)[axis] * a.length * a.actors[axis].GetScale()[axis] * fraction
    xy = np.round(_display(window, grab)).astype(int)
    iren = window.plotter.iren.interactor
    iren.SetEventInformation(int(xy[0]), int(xy[1]))
    iren.InvokeEvent("LeftButtonPressEvent")
    return xy, grab


def _move_along_arrow(window, axis, start_xy, pixels, steps=6):
    """Move the mouse ``pixels`` along the arrow's on-screen direction; returns the end pixel."""
    a = window.axes
    base = _display(window, a.position())
    tip = _display(window, a.position() + np.eye(3)[axis] * a.length)
    u = (tip - base) / np.linalg.norm(tip - base)
    iren = window.plotter.iren.interactor
    for step in range(1, steps + 1):
        xy = np.round(start_xy + u * pixels * step / steps).astype(int)
        iren.SetEventInformation(int(xy[0]), int(xy[1]))
        iren.InvokeEvent("MouseMoveEvent")
    return xy


def _release(window):
    window.plotter.iren.interactor.InvokeEvent("LeftButtonReleaseEvent")


def test_x_arrow_drag_in_pose_mode_translates_root_along_x(window):
    doc = window.document
    rig, sk = doc.rig, doc.skeleton
    doc.select(0)
    window.set_axis(1)  # the toolbar says Y: the grabbed X arrow still drags along X
    rest = doc.pose_snapshot()
    before = window.scene.mesh.points.copy()
    xy, grab = _press_arrow(window, 0)
    assert window.axes.grabbed == 0
    assert window.gizmos.active is None  # the press did not also start a sphere drag
    assert window.axes.actors[0].GetProperty().GetColor() != window.axes.actors[1]\
        .GetProperty().GetColor()
    end = _move_along_arrow(window, 0, xy, 120)
    mid = window.scene.mesh.points.copy()
    assert np.abs(mid - before).max() > 0.02 * rig.height()  # the mesh follows during the drag
    _release(window)
    assert window.axes.grabbed is None and window.gizmos.active is None
    moved = doc.pose.translation[0] - sk.rest_translation[0]
    assert abs(moved[0]) > 0.05 * rig.height()
    np.testing.assert_allclose(moved[1:], 0.0, atol=1e-9)
    # the whole mesh shifted along X only
    np.testing.assert_allclose(window.scene.mesh.points[:, 1:], before[:, 1:], atol=1e-4)
    # the grabbed point of the arrow stayed under the mouse
    np.testing.assert_allclose(_display(window, grab + [moved[0], 0, 0]), end, atol=1.5)
    # the sphere and the arrows sit on the joint
    head = rig.joint_matrices(doc.pose)[0, :3, 3]
    np.testing.assert_allclose(window.gizmos.center(0), head, atol=1e-6)
    np.testing.assert_allclose(window.axes.position(), head, atol=1e-6)
    assert len(doc.undo_stack) == 1
    window.undo_action.trigger()
    np.testing.assert_array_equal(doc.pose_snapshot(), rest)
    np.testing.assert_allclose(window.scene.mesh.points, before, atol=1e-6)


def test_x_arrow_drag_in_edit_mode_moves_rest_position_along_x(window, qtbot):
    doc = window.document
    rig = doc.rig
    sk0, binding0 = doc.skeleton, rig.binding
    j = _limb_joint(sk0)
    window.set_mode("edit")
    doc.select(j)
    start = sk0.bind_matrices[j, :3, 3].copy()
    xy, _ = _press_arrow(window, 0)
    assert window.axes.grabbed == 0 and window.gizmos.active is None
    _move_along_arrow(window, 0, xy, -90)
    # during the drag the sphere and the bone follow, on the axis
    mid = window.gizmos.center(j)
    np.testing.assert_allclose(mid[1:], start[1:], atol=1e-9)
    assert abs(mid[0] - start[0]) > 0.02 * rig.height()
    _release(window)
    assert window.job is not None  # re-binding, as after a sphere drag
    qtbot.waitUntil(lambda: window.job is None, timeout=30000)
    head = doc.skeleton.bind_matrices[j, :3, 3]
    assert abs(head[0] - start[0]) > 0.02 * rig.height()
    np.testing.assert_allclose(head[1:], start[1:], atol=1e-9)
    assert doc.rig.binding is not binding0
    np.testing.assert_allclose(window.gizmos.center(j), head, atol=1e-6)
    assert len(doc.undo_stack) == 1
    window.undo_action.trigger()
    assert doc.skeleton is sk0 and doc.rig.binding is binding0
    np.testing.assert_array_equal(doc.skeleton.bind_matrices[j, :3, 3], start)
    window.set_mode("pose")


def test_press_on_empty_background_moves_no_joint_but_turns_the_camera(window):
    doc = window.document
    doc.select(0)
    window.plotter.render()
    rest = doc.pose_snapshot()
    points = window.scene.mesh.points.copy()
    cam = np.array(window.plotter.camera.position)
    iren = window.plotter.iren.interactor
    iren.SetEventInformation(15, 15)  # a corner of the view: nothing there
    iren.InvokeEvent("LeftButtonPressEvent")
    assert window.axes.grabbed is None and window.gizmos.active is None
    for step in range(1, 6):
        iren.SetEventInformation(15 + 20 * step, 15 + 5 * step)
        iren.InvokeEvent("MouseMoveEvent")
    iren.InvokeEvent("LeftButtonReleaseEvent")
    np.testing.assert_array_equal(doc.pose_snapshot(), rest)
    np.testing.assert_array_equal(window.scene.mesh.points, points)
    assert len(doc.undo_stack) == 0
    assert np.linalg.norm(np.array(window.plotter.camera.position) - cam) > 1e-6


def test_sphere_press_still_drags_the_sphere_with_handles_shown(window):
    doc = window.document
    sk = doc.skeleton
    j = _limb_joint(sk)
    doc.select(j)
    window.plotter.render()
    x, y = window.gizmos.display_position(j)
    assert window.axes.pick(x, y) is None  # the joint's centre belongs to its sphere
    iren = window.plotter.iren.interactor
    iren.SetEventInformation(int(round(x)), int(round(y)))
    iren.InvokeEvent("LeftButtonPressEvent")
    assert window.gizmos.active == j and window.axes.grabbed is None
    for step in range(1, 5):
        iren.SetEventInformation(int(round(x)) + 8 * step, int(round(y)) + 6 * step)
        iren.InvokeEvent("MouseMoveEvent")
    iren.InvokeEvent("LeftButtonReleaseEvent")
    assert window.gizmos.active is None and len(doc.undo_stack) == 1


def test_hidden_handles_do_not_take_presses(window):
    doc = window.document
    doc.select(0)
    window.plotter.render()
    a = window.axes
    tip = _display(window, a.position() + np.eye(3)[0] * a.length * 0.85)
    assert a.pick(*tip) == 0
    window.set_gizmos_visible(False)
    assert a.pick(*tip) is None
    window.set_gizmos_visible(True)
    doc.select(None)
    assert a.pick(*tip) is None
