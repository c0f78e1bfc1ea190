"""Races around the edit-mode re-bind (a rest move re-binds the skin in a worker): pose edits
made while it runs are kept, a second rest move is refused, undo cancels it, and a result
computed for a rig or skeleton that was replaced meanwhile is dropped. Each goes through the
real path: a gizmo drag in edit mode starts the job, which a slow weights function holds open.
"""
import threading

import numpy as np
import pytest

pytestmark = [pytest.mark.ui, pytest.mark.filterwarnings("error::RuntimeWarning")]

from ui_window_fixture import limb_joint  # noqa: E402


@pytest.fixture
def gate(monkeypatch):
    """Holds every re-bind and weights job open until ``gate.set()`` (cancel still works
    meanwhile)."""
    from rigedit.editor import recompute
    from rigedit.ui import rebind

    event = threading.Event()
    real = recompute.compute_weights_for

    def slow(vertices, skeleton, *args, progress=None, **kw):
        while not event.wait(0.01):
            progress(0.0)  # raises Cancelled once the user cancelled
        return real(vertices, skeleton, *args, progress=progress, **kw)

    monkeypatch.setattr(rebind, "compute_weights_for", slow)       # edit-mode re-binds
    monkeypatch.setattr(recompute, "compute_weights_for", slow)    # File > Recompute weights
    yield event
    event.set()




def _start_rebind(window, j, up=0.05):
    window.set_mode("edit")
    start = window.gizmos.center(j)
    target = start + np.array([0.0, up, 0.0]) * window.document.rig.height()
    window.gizmos.drag(j, target)
    assert window.job is not None and window.job.isRunning()
    return target


def _state(doc):
    return doc.skeleton, doc.rig.binding, doc.pose_snapshot()


def _assert_state(doc, state):
    assert doc.skeleton is state[0] and doc.rig.binding is state[1]
    np.testing.assert_array_equal(doc.pose_snapshot(), state[2])


def test_pose_edits_made_while_rebinding_are_kept(window, qtbot, gate):
    doc = window.document
    sk = doc.skeleton
    j = limb_joint(sk)
    head = sk.index["head"]
    s0 = _state(doc)
    target = _start_rebind(window, j)
    # While the worker runs: back to pose mode, drag the head's sphere (the real gizmo path)
    # and type an angle into the joint panel.
    window.set_mode("pose")
    window.chain_length = 1
    window.gizmos.drag(head, window.gizmos.center(head) + np.array([0.0, 0.0, 0.15]) * doc.rig.height())
    s1 = _state(doc)
    assert not np.array_equal(s1[2], s0[2])
    doc.select(j)
    window.joint_panel.angle_boxes[0].setValue(30.0)
    s2 = _state(doc)
    assert window.job is not None  # both edits landed while the re-bind was still running
    gate.set()
    qtbot.waitUntil(lambda: window.job is None, timeout=30000)
    s3 = _state(doc)
    np.testing.assert_allclose(doc.skeleton.bind_matrices[j, :3, 3], target, atol=1e-9)
    # Kept: the local rotations are exactly those of the edits, the translations keep their
    # offsets from the (moved) rest pose.
    np.testing.assert_array_equal(s3[2][:, 3:], s2[2][:, 3:])
    np.testing.assert_allclose(s3[2][:, :3] - doc.skeleton.rest_translation,
                               s2[2][:, :3] - sk.rest_translation, atol=1e-12)
    np.testing.assert_allclose(doc.pose.get_euler(j, degrees=True), [30, 0, 0], atol=1e-9)
    assert "re-bound" in window.statusBar().currentMessage()
    # Undo and redo walk back and forth through exact states.
    assert doc.undo_stack.undo_label.endswith("(rest)")
    for expected in (s2, s1, s0):
        window.undo_action.trigger()
        _assert_state(doc, expected)
    for expected in (s1, s2, s3):
        window.redo_action.trigger()
        _assert_state(doc, expected)
    window.set_mode("pose")


def test_rebind_finishing_during_a_pose_drag_waits_for_its_end(window, qtbot, gate):
    doc = window.document
    sk = doc.skeleton
    j, head = limb_joint(sk), sk.index["head"]
    s0 = _state(doc)
    _start_rebind(window, j)
    window.set_mode("pose")
    window.chain_length = 1
    g = window.gizmos
    g.start_drag(head)
    g.drag_to(g.center(head) + np.array([0.0, 0.0, 0.15]) * doc.rig.height())
    gate.set()
    qtbot.waitUntil(lambda: window.job is None, timeout=30000)
    qtbot.wait(200)
    assert doc.skeleton is sk and doc.dragging  # held back while the drag is held
    g.end_drag()
    s1 = (sk, s0[1], doc.pose_snapshot())
    qtbot.waitUntil(lambda: doc.skeleton is not sk, timeout=5000)
    s2 = _state(doc)
    np.testing.assert_array_equal(s2[2][:, 3:], s1[2][:, 3:])  # the drag's rotations kept
    for expected in (s1, s0):
        window.undo_action.trigger()
        _assert_state(doc, expected)
    for expected in (s1, s2):
        window.redo_action.trigger()
        _assert_state(doc, expected)


def test_second_rest_move_while_rebinding_is_refused(window, qtbot, gate):
    doc = window.document
    sk = doc.skeleton
    j = limb_joint(sk)
    k = sk.index["head"]
    head_rest = sk.bind_matrices[k, :3, 3].copy()
    target = _start_rebind(window, j)
    window.gizmos.drag(k, window.gizmos.center(k) + [0.0, 0.2, 0.0])
    message = window.statusBar().currentMessage()
    assert "Busy" in message and "head keeps its rest position" in message
    assert window.last_error is None  # a status message, no error dialog
    np.testing.assert_allclose(window.gizmos.center(k), head_rest, atol=1e-9)  # snapped back
    gate.set()
    qtbot.waitUntil(lambda: window.job is None, timeout=30000)
    np.testing.assert_allclose(doc.skeleton.bind_matrices[j, :3, 3], target, atol=1e-9)
    np.testing.assert_array_equal(doc.skeleton.bind_matrices[k, :3, 3], head_rest)
    assert len(doc.undo_stack) == 1
    window.set_mode("pose")


def test_undo_while_rebinding_cancels_it_when_it_is_the_latest_edit(window, qtbot, gate):
    doc = window.document
    j = limb_joint(doc.skeleton)
    doc.set_joint_euler(doc.skeleton.index["head"], [0, 15, 0])
    s0 = _state(doc)
    _start_rebind(window, j)
    assert window.undo_action.isEnabled() and window.undo_action.text().endswith("(rest)")
    window.undo_action.trigger()
    qtbot.waitUntil(lambda: window.job is None, timeout=10000)
    _assert_state(doc, s0)  # the rest move is gone, the earlier pose edit is not
    assert len(doc.undo_stack) == 1 and "cancelled" in window.statusBar().currentMessage()
    window.undo_action.trigger()  # the next undo reverts the pose edit
    np.testing.assert_array_equal(doc.pose_snapshot(), doc.rig.rest_pose().as_array())
    window.set_mode("pose")


def test_undo_of_an_edit_made_while_rebinding_leaves_the_rebind_running(window, qtbot, gate):
    doc = window.document
    j = limb_joint(doc.skeleton)
    s0 = _state(doc)
    _start_rebind(window, j)
    doc.set_joint_euler(doc.skeleton.index["head"], [0, 15, 0])
    window.undo_action.trigger()  # undoes the pose edit, the newest
    assert window.job is not None
    np.testing.assert_array_equal(doc.pose_snapshot(), s0[2])
    gate.set()
    qtbot.waitUntil(lambda: window.job is None, timeout=30000)
    assert doc.skeleton is not s0[0] and len(doc.undo_stack) == 1
    window.undo_action.trigger()
    _assert_state(doc, s0)
    window.set_mode("pose")


def test_result_for_a_replaced_rig_is_dropped(window, qtbot, gate):
    from rigedit.ui.fallback import demo_rig

    doc = window.document
    _start_rebind(window, limb_joint(doc.skeleton))
    window.files.open_folder("/nonexistent")  # File > Open is refused while a job runs
    assert "busy with 'Re-binding" in window.statusBar().currentMessage()
    window._last_dialog.close()
    other = demo_rig()
    doc.set_rig(other)  # ... but the API may still replace the rig
    sk, binding = other.skeleton, other.binding
    gate.set()
    qtbot.waitUntil(lambda: window.job is None, timeout=30000)
    assert doc.rig is other and doc.skeleton is sk and doc.rig.binding is binding
    assert len(doc.undo_stack) == 0
    assert "dropped: another rig was opened" in window.statusBar().currentMessage()


def test_result_for_a_replaced_skeleton_is_dropped(window, qtbot, gate):
    doc = window.document
    j = limb_joint(doc.skeleton)
    _start_rebind(window, j, up=0.03)
    gate.set()
    qtbot.waitUntil(lambda: window.job is None, timeout=30000)
    moved = _state(doc)
    window.undo_action.trigger()
    gate.clear()
    _start_rebind(window, j, up=-0.03)  # a second move, from the original rest
    window.redo_action.trigger()  # redo the first move while the second one runs
    _assert_state(doc, moved)
    gate.set()
    qtbot.waitUntil(lambda: window.job is None, timeout=30000)
    _assert_state(doc, moved)  # the second result, computed for the old skeleton, is dropped
    assert "skeleton or the weights changed" in window.statusBar().currentMessage()
    window.set_mode("pose")


def test_recomputed_weights_for_an_undone_skeleton_are_dropped(window, qtbot, gate):
    from rigedit.editor.document import skeleton_with_moved_joint

    doc = window.document
    j = limb_joint(doc.skeleton)
    before = doc.rest_state()
    moved = skeleton_with_moved_joint(doc.skeleton, j, doc.skeleton.bind_matrices[j, :3, 3] + 0.05)
    doc.push_rest_edit("Move (rest)", before, (moved, before[1], before[2]))
    assert window.files.recompute_weights() is not None
    window.undo_action.trigger()  # the rest move goes while the weights are computed for it
    assert doc.skeleton is before[0]
    gate.set()
    qtbot.waitUntil(lambda: window.job is None, timeout=30000)
    _assert_state(doc, before)
    assert "dropped: the skeleton changed" in window.statusBar().currentMessage()
    assert not doc.undo_stack.can_undo and doc.undo_stack.can_redo
