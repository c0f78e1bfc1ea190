"""The joint panel through its widgets (real mouse and key events on a window under Xvfb): a
rotation slider drag is one undo step, the translation and scale boxes pose the joint and
undo, Mirror R -> L reflects the right side onto the left."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

pytestmark = [pytest.mark.ui, pytest.mark.filterwarnings("error::RuntimeWarning")]

from PyQt5 import QtCore, QtWidgets  # noqa: E402

from ui_window_fixture import limb_joint, send_mouse  # noqa: E402


def _mouse(widget, kind, pos):
    send_mouse(widget, kind, pos.x(), pos.y())


def _handle_center(slider):
    opt = QtWidgets.QStyleOptionSlider()
    slider.initStyleOption(opt)
    return slider.style().subControlRect(QtWidgets.QStyle.CC_Slider, opt,
                                         QtWidgets.QStyle.SC_SliderHandle, slider).center()


def _x_of(slider, value):
    """Pixel x of the handle's centre at ``value``."""
    opt = QtWidgets.QStyleOptionSlider()
    slider.initStyleOption(opt)
    style = slider.style()
    groove = style.subControlRect(QtWidgets.QStyle.CC_Slider, opt,
                                  QtWidgets.QStyle.SC_SliderGroove, slider)
    handle = style.subControlRect(QtWidgets.QStyle.CC_Slider, opt,
                                  QtWidgets.QStyle.SC_SliderHandle, slider)
    span = groove.width() - handle.width()
    return groove.x() + handle.width() / 2 + QtWidgets.QStyle.sliderPositionFromValue(
        slider.minimum(), slider.maximum(), value, span)


def _drag_slider(slider, values):
    """Press the handle, move through ``values`` (slider units), release."""
    start = _handle_center(slider)
    y = start.y()
    _mouse(slider, "press", start)
    assert slider.isSliderDown()
    pos = start
    for v in values:
        pos = QtCore.QPoint(int(round(_x_of(slider, int(v)))), y)
        _mouse(slider, "move", pos)
    _mouse(slider, "release", pos)
    assert not slider.isSliderDown()


@pytest.mark.parametrize("axis, end", [(0, 40.0), (1, 120.0)])
def test_slider_drag_is_one_undo_step_and_undo_restores_the_pose(window, axis, end):
    doc = window.document
    j = limb_joint(doc.skeleton)
    doc.select(j)
    panel = window.joint_panel
    slider = panel.sliders[axis]
    rest = doc.pose_snapshot()
    points = window.scene.mesh.points.copy()
    steps = np.linspace(0, end, 6)[1:]
    rest_q = Rotation.from_quat(doc.skeleton.rest_rotation[j])
    seen = []   # the joint's angle from rest at each pose change during the drag
    doc.subscribe(lambda event, **_: event == "pose" and seen.append(np.degrees(
        (rest_q.inv() * Rotation.from_quat(doc.pose.rotation[j])).magnitude())))
    _drag_slider(slider, steps * 10)
    # the joint followed the handle step by step, ending where the handle was let go
    assert len(seen) >= 5 and seen[0] < 0.5 * end
    assert np.all(np.diff(seen) > 0), seen
    expected = np.zeros(3)
    expected[axis] = slider.value() / 10
    assert abs(expected[axis] - end) < 2.0    # within a pixel's worth of slider units
    q = Rotation.from_quat(doc.pose.rotation[j])
    want = Rotation.from_quat(doc.skeleton.rest_rotation[j]) * Rotation.from_euler(
        "xyz", expected, degrees=True)
    assert (q.inv() * want).magnitude() < 1e-9
    assert panel.angle_boxes[axis].value() == pytest.approx(expected[axis])
    assert np.abs(window.scene.mesh.points - points).max() > 1e-3
    assert len(doc.undo_stack) == 1
    assert doc.undo_stack.undo_label == f"Rotate {doc.skeleton.names[j]}"
    dragged = doc.pose_snapshot()
    window.undo_action.trigger()
    np.testing.assert_array_equal(doc.pose_snapshot(), rest)
    np.testing.assert_allclose(window.scene.mesh.points, points, atol=1e-6)
    assert slider.value() == 0 and panel.angle_boxes[axis].value() == 0.0
    window.redo_action.trigger()
    np.testing.assert_array_equal(doc.pose_snapshot(), dragged)


def test_the_two_euler_triples_are_one_rotation():
    from rigedit.ui.joint_panel import nearest_euler

    rng = np.random.default_rng(3)
    for a in rng.uniform(-179, 179, (20, 3)) * [1, 0.49, 1]:
        other = nearest_euler(a, a * [1, -1, 1] + [180, 180, 180])
        assert np.abs(other - a).max() > 1.0      # the other triple was chosen
        r = Rotation.from_euler("xyz", a, degrees=True)
        assert (r.inv() * Rotation.from_euler("xyz", other, degrees=True)).magnitude() < 1e-9
        np.testing.assert_allclose(nearest_euler(a, a + 0.5), a)


def _type(qtbot, box, text):
    """Type ``text`` into a spin box and press Return, as a user does."""
    box.setFocus()
    box.selectAll()
    qtbot.keyClicks(box, text)
    qtbot.keyClick(box, QtCore.Qt.Key_Return)


def test_typed_rotation_past_90_degrees_stays_as_typed(window, qtbot):
    doc = window.document
    j = limb_joint(doc.skeleton)
    window.joint_panel.tree.setCurrentItem(window.joint_panel._items[j])
    box = window.joint_panel.angle_boxes[1]
    _type(qtbot, box, "120")
    assert box.value() == 120.0 and window.joint_panel.sliders[1].value() == 1200
    assert [b.value() for b in window.joint_panel.angle_boxes] == [0.0, 120.0, 0.0]
    r = Rotation.from_quat(doc.pose.rotation[j])
    assert (r.inv() * Rotation.from_euler("y", 120, degrees=True)).magnitude() < 1e-9


def test_translation_and_scale_boxes_pose_the_joint_and_undo(window, qtbot):
    doc = window.document
    sk = doc.skeleton
    j = limb_joint(sk)
    panel = window.joint_panel
    panel.tree.setCurrentItem(panel._items[j])
    assert doc.selection == j
    rest = doc.pose_snapshot()
    points = window.scene.mesh.points.copy()
    heads0 = window.scene.joint_positions.copy()
    t0 = sk.rest_translation[j].copy()
    _type(qtbot, panel.translation_boxes[1], f"{t0[1] + 0.05:.3f}")
    assert doc.pose.translation[j][1] == pytest.approx(round(t0[1] + 0.05, 3), abs=1e-12)
    np.testing.assert_array_equal(doc.pose.translation[j][[0, 2]], t0[[0, 2]])
    assert doc.undo_stack.undo_label == f"Move {sk.names[j]}"
    # the joint (and only its subtree) moved up by 5 cm in its parent's frame (rest frames
    # are axis-aligned in the bundled rigs)
    heads = window.scene.joint_positions
    sub = sk.subtree(j)
    np.testing.assert_allclose(heads[sub] - heads0[sub],
                               np.tile([0, doc.pose.translation[j][1] - t0[1], 0], (len(sub), 1)),
                               atol=1e-9)
    others = np.setdiff1d(np.arange(len(sk)), sub)
    np.testing.assert_array_equal(heads[others], heads0[others])
    moved = window.scene.mesh.points.copy()
    assert np.abs(moved - points).max() > 0.02
    _type(qtbot, panel.scale_boxes[0], "1.5")
    _type(qtbot, panel.scale_boxes[2], "0.5")
    np.testing.assert_array_equal(doc.pose.scale[j], [1.5, 1.0, 0.5])
    assert doc.undo_stack.undo_label == f"Scale {sk.names[j]}"
    assert np.abs(window.scene.mesh.points - moved).max() > 1e-3
    assert len(doc.undo_stack) == 3
    for _ in range(3):
        window.undo_action.trigger()
    np.testing.assert_array_equal(doc.pose_snapshot(), rest)
    np.testing.assert_allclose(window.scene.mesh.points, points, atol=1e-6)
    assert panel.translation_boxes[1].value() == pytest.approx(t0[1], abs=1e-3)
    assert [b.value() for b in panel.scale_boxes] == [1.0, 1.0, 1.0]


def test_mirror_right_to_left(window, qtbot):
    doc = window.document
    sk = doc.skeleton
    pairs = [(sk.index[n], sk.index[n[:-2] + "_L"]) for n in sk.names if n.endswith("_R")]
    assert len(pairs) >= 10
    right = [r for r, _ in pairs]
    left = [l for _, l in pairs]
    heads0 = window.scene.joint_positions.copy()
    # the rest skeleton is symmetric across x = 0 (the quadruped's left is +X)
    np.testing.assert_allclose(heads0[left], heads0[right] * [-1, 1, 1], atol=1e-6)
    panel = window.joint_panel
    posed = {"fore_upper_R": ("10", "-25", "30"), "hind_shin_R": ("-40", "15", "5"),
             "fore_upper_L": ("0", "50", "0")}   # the left one is overwritten by the mirror
    for name, angles in posed.items():
        panel.tree.setCurrentItem(panel._items[sk.index[name]])
        for box, text in zip(panel.angle_boxes, angles):
            _type(qtbot, box, text)
    upper_r = sk.index["fore_upper_R"]
    panel.tree.setCurrentItem(panel._items[upper_r])
    _type(qtbot, panel.translation_boxes[0], f"{sk.rest_translation[upper_r, 0] - 0.04:.3f}")
    before = doc.pose_snapshot()
    n = len(doc.undo_stack)
    panel.mirror_rl_button.click()
    assert len(doc.undo_stack) == n + 1
    flip = np.diag([-1.0, 1.0, 1.0])
    for r, l in pairs:
        want = Rotation.from_matrix(flip @ Rotation.from_quat(doc.pose.rotation[r]).as_matrix()
                                    @ flip)
        got = Rotation.from_quat(doc.pose.rotation[l])
        assert (got.inv() * want).magnitude() < 1e-9, sk.names[l]
        np.testing.assert_allclose(doc.pose.translation[l], doc.pose.translation[r] * [-1, 1, 1],
                                   atol=1e-12)
    # the right side is untouched, and the posed left joint shows mirrored angles
    np.testing.assert_array_equal(doc.pose_snapshot()[right], before[right])
    np.testing.assert_allclose(doc.pose.get_euler("fore_upper_L", degrees=True), [10, 25, -30],
                               atol=1e-9)
    # the whole left side now stands as the mirror image of the right
    heads = window.scene.joint_positions
    assert np.abs(heads[right] - heads0[right]).max() > 0.05
    np.testing.assert_allclose(heads[left], heads[right] * [-1, 1, 1], atol=1e-6)
    window.undo_action.trigger()
    np.testing.assert_array_equal(doc.pose_snapshot(), before)
