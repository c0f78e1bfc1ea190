"""The joint spheres under the mouse in the editor window (under Xvfb): hover highlight,
nearest-first picking of joints one behind the other, presses beside every sphere going to the
camera, and a whole drag through Qt's own mouse events."""

import numpy as np
import pytest

pytestmark = [pytest.mark.ui, pytest.mark.filterwarnings("error::RuntimeWarning")]

from ui_window_fixture import limb_joint, send_mouse  # noqa: E402


def _event(window, kind, x, y):
    iren = window.plotter.iren.interactor
    iren.SetEventInformation(int(round(x)), int(round(y)))
    iren.InvokeEvent({"press": "LeftButtonPressEvent", "move": "MouseMoveEvent",
                      "release": "LeftButtonReleaseEvent"}[kind])


def _empty_pixel(window):
    """A display pixel of the view far from every joint sphere (a corner)."""
    w, h = window.plotter.render_window.GetSize()
    for x, y in ((10, 10), (w - 10, 10), (10, h - 10), (w - 10, h - 10)):
        if window.gizmos.pick(x, y) is None:
            return x, y
    pytest.fail("expected a corner of the view without a joint sphere")


def test_hover_highlights_the_sphere_a_press_would_grab(window):
    g = window.gizmos
    j = limb_joint(window.document.skeleton)
    window.plotter.render()
    plain = g.glyphs.color_of(j).copy()
    _event(window, "move", *g.display_position(j))
    assert g.hovered == j
    assert np.all(g.glyphs.color_of(j) >= plain) and g.glyphs.color_of(j).sum() > plain.sum()
    _event(window, "move", *_empty_pixel(window))
    assert g.hovered is None
    np.testing.assert_allclose(g.glyphs.color_of(j), plain)
    _event(window, "move", *g.display_position(j))
    assert g.hovered == j
    window.plotter.iren.interactor.InvokeEvent("LeaveEvent")  # the mouse left the view
    assert g.hovered is None


def test_joints_one_behind_the_other_pick_the_nearer(window):
    """The camera put on the line through the left and the right fore cannon: a press on
    the pair grabs the one nearer the camera, from either side."""
    sk = window.document.skeleton
    g = window.gizmos
    camera = window.plotter.renderer.GetActiveCamera()
    a, b = sk.index["fore_cannon_L"], sk.index["fore_cannon_R"]
    pa, pb = g.center(a), g.center(b)
    axis = (pa - pb) / np.linalg.norm(pa - pb)
    for near, far, sign in ((a, b, 1.0), (b, a, -1.0)):
        camera.SetFocalPoint(*g.center(far))
        camera.SetPosition(*(g.center(near) + sign * 2.0 * axis))
        camera.SetViewUp(0.0, 1.0, 0.0)
        window.plotter.renderer.ResetCameraClippingRange()
        window.plotter.render()
        xa, ya = g.display_position(a)
        xb, yb = g.display_position(b)
        assert np.hypot(xa - xb, ya - yb) < 0.5  # one behind the other on screen
        assert g.pick(xa, ya) == near
        assert g.pick(xa + 1, ya - 1) == near  # off-centre too


def test_press_beside_every_sphere_turns_the_camera_and_edits_nothing(window):
    cam = window.plotter.renderer.GetActiveCamera()
    before = np.array(cam.GetPosition())
    x, y = _empty_pixel(window)
    _event(window, "press", x, y)
    assert window.gizmos.active is None and not window.interacting
    for k in range(1, 6):
        _event(window, "move", x + 15 * k, y + 5 * k)
    _event(window, "release", x + 75, y + 25)
    assert np.linalg.norm(np.array(cam.GetPosition()) - before) > 1e-3  # the view turned
    assert len(window.document.undo_stack) == 0 and window.document.selection is None


def test_drag_through_qt_mouse_events_is_one_undo_step(window, qtbot):
    doc = window.document
    j = limb_joint(doc.skeleton)
    window.view("side")
    window.plotter.render()
    rest = doc.pose_snapshot()
    x, y = window.gizmos.display_position(j)
    h = window.plotter.height()
    qx, qy = x, h - 1 - y  # Qt's y grows downwards
    view = window.plotter
    send_mouse(view, "press", qx, qy)
    assert window.gizmos.active == j and window.interacting
    for k in range(1, 6):
        send_mouse(view, "move", qx + 6 * k, qy - 4 * k)
    assert not np.array_equal(doc.pose_snapshot(), rest)  # posed during the drag
    send_mouse(view, "release", qx + 30, qy - 20)
    assert window.gizmos.active is None and not window.interacting
    assert len(doc.undo_stack) == 1 and doc.undo_stack.undo_label == "Drag fore_cannon_L"
    model = doc.rig.joint_matrices(doc.pose)
    np.testing.assert_allclose(window.gizmos.center(j), model[j, :3, 3], atol=1e-6)
    window.undo_action.trigger()
    np.testing.assert_array_equal(doc.pose_snapshot(), rest)
    np.testing.assert_allclose(window.gizmos.center(j),
                               doc.rig.joint_matrices(doc.pose)[j, :3, 3], atol=1e-6)


def test_non_deforming_joints_are_drawn_apart_and_follow_the_flag(window):
    doc = window.document
    sk = doc.skeleton
    g = window.gizmos
    root, spine = sk.index["root"], sk.index["spine_1"]
    assert not sk.deform[root] and sk.deform[spine]
    assert not np.allclose(g.glyphs.color_of(root), g.glyphs.color_of(spine))
    doc.select(spine)
    window.joint_panel.deform_box.click()  # the joint panel's Deforms box: an undoable edit
    assert not doc.skeleton.deform[spine]
    doc.select(None)  # no longer drawn as selected: in the non-deforming colour
    from rigedit.render.joint_glyphs import CARRIER_COLOR, NON_DEFORMING_COLOR

    np.testing.assert_allclose(g.glyphs.color_of(spine), NON_DEFORMING_COLOR, atol=1e-2)
    # the quadruped's root is a carrier (it only moves the figure): dimmer still
    np.testing.assert_allclose(g.glyphs.color_of(root), CARRIER_COLOR, atol=1e-2)
    window.undo_action.trigger()
    assert doc.skeleton.deform[spine]
    assert not np.allclose(g.glyphs.color_of(spine), NON_DEFORMING_COLOR, atol=1e-2)


@pytest.fixture
def fk_calls(monkeypatch):
    """Counts forward kinematics (``local_to_model``) wherever rigedit imported it."""
    import sys

    from rigedit.model import kinematics

    original = kinematics.local_to_model
    calls = []

    def counting(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)

    for name, module in list(sys.modules.items()):
        if name.startswith("rigedit") and getattr(module, "local_to_model", None) is original:
            monkeypatch.setattr(module, "local_to_model", counting)
    return calls


@pytest.mark.parametrize("chain", [1, 2, 3])
def test_a_drag_step_runs_forward_kinematics_once(window, fk_calls, chain):
    # The IK of each step starts from the pose at the press, whose FK is computed once at
    # the press; the step's own FK is the view's, for the new pose (issue 18).
    doc = window.document
    j = limb_joint(doc.skeleton)
    window.chain_length = chain
    window.view("side")
    view = window.plotter
    view.render()
    x, y = window.gizmos.display_position(j)
    qx, qy = x, view.height() - 1 - y  # Qt's y grows downwards
    send_mouse(view, "press", qx, qy)
    assert window.gizmos.active == j
    per_step = []
    for k in range(1, 6):
        before = len(fk_calls)
        send_mouse(view, "move", qx + 6 * k, qy - 4 * k)
        per_step.append(len(fk_calls) - before)
    send_mouse(view, "release", qx + 30, qy - 20)
    assert len(doc.undo_stack) == 1   # the moves were drag steps
    assert per_step == [1] * 5, per_step
