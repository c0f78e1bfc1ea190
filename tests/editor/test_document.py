"""The document: undo stack, pose edits as commands, drags as one step, mirror, rest edits."""
import numpy as np
import pytest

from builders import chain_skeleton, cylinder_rig
from rigedit.editor.document import (Command, Document, UndoStack, mirror_map, mirror_name,
                              skeleton_with_moved_joint)


@pytest.fixture
def doc():
    return Document(cylinder_rig())


def test_undo_stack_push_undo_redo_and_redo_cleared():
    log = []
    s = UndoStack()
    s.push(Command("a", lambda: log.append("do a"), lambda: log.append("undo a")))
    s.push(Command("b", lambda: log.append("do b"), lambda: log.append("undo b")))
    assert s.undo_label == "b"
    assert s.undo().label == "b"
    assert s.redo_label == "b" and s.can_redo
    s.push(Command("c", lambda: log.append("do c"), lambda: log.append("undo c")))
    assert not s.can_redo  # a new edit drops the redo history
    assert s.redo() is None
    assert log == ["do a", "do b", "undo b", "do c"]
    assert [s.undo().label, s.undo().label, s.undo()] == ["c", "a", None]


def test_undo_stack_limit_and_observers():
    s = UndoStack(limit=3)
    calls = []
    s.observers.append(lambda: calls.append(len(s)))
    for i in range(5):
        s.push(Command(str(i), lambda: None, lambda: None), execute=False)
    assert len(s) == 3 and s.undo_label == "4"
    assert calls == [1, 2, 3, 3, 3]


def test_edit_pose_is_one_undo_step_restoring_exactly(doc):
    events = []
    doc.subscribe(lambda e, **kw: events.append(e))
    before = doc.pose_snapshot()
    doc.set_joint_euler(1, [10, 20, 30])
    np.testing.assert_allclose(doc.pose.get_euler(1, degrees=True), [10, 20, 30])
    after = doc.pose_snapshot()
    assert "pose" in events and "undo" in events
    doc.undo()
    np.testing.assert_array_equal(doc.pose_snapshot(), before)
    doc.redo()
    np.testing.assert_array_equal(doc.pose_snapshot(), after)


def test_no_op_edit_makes_no_undo_step(doc):
    doc.set_joint_euler(1, [0, 0, 0])
    assert not doc.undo_stack.can_undo


def test_drag_is_one_step(doc):
    before = doc.pose_snapshot()
    doc.begin_drag()
    for a in range(1, 6):
        doc.pose.set_euler(1, [a * 5, 0, 0], degrees=True)
        doc.set_pose(doc.pose)
    doc.end_drag("Drag j1")
    assert len(doc.undo_stack) == 1 and doc.undo_stack.undo_label == "Drag j1"
    doc.undo()
    np.testing.assert_array_equal(doc.pose_snapshot(), before)


def test_reset_and_set_pose_validation(doc):
    doc.set_joint_translation(0, [1, 2, 3])
    doc.set_joint_scale(1, [2, 2, 2])
    doc.reset_pose()
    assert doc.pose.allclose(doc.rig.rest_pose())
    doc.undo()
    np.testing.assert_array_equal(doc.pose.scale[1], [2, 2, 2])
    with pytest.raises(ValueError, match="expected a pose of"):
        doc.set_pose(np.zeros((1, 10)))


def test_selection_event(doc):
    seen = []
    doc.subscribe(lambda e, **kw: seen.append((e, kw.get("joint"))))
    doc.select("j1")
    doc.select("j1")  # unchanged: no event
    doc.select(None)
    assert seen == [("selection", 1), ("selection", None)]


@pytest.mark.parametrize("name,other", [("arm_L", "arm_R"), ("hand.R", "hand.L"),
                                        ("LeftFoot", "RightFoot"), ("thigh_L_01", "thigh_R_01"),
                                        ("spine", None), ("l_ear", "r_ear")])
def test_mirror_name(name, other):
    assert mirror_name(name) == other


def test_mirror_map():
    assert mirror_map(["a_L", "b", "a_R", "c_L"]).tolist() == [2, 1, 0, 3]


def test_mirror_pose_reflects_left_onto_right():
    from rigedit.ui.fallback import demo_rig

    doc = Document(demo_rig())
    sk = doc.skeleton
    left, right = sk.joint_index("front_thigh_L"), sk.joint_index("front_thigh_R")
    doc.set_joint_euler(left, [20, 15, -10])
    doc.mirror_pose("L")
    model = doc.rig.joint_matrices(doc.pose)
    # The feet end up mirror images across x = 0.
    fl, fr = sk.joint_index("front_foot_L"), sk.joint_index("front_foot_R")
    np.testing.assert_allclose(model[fr, :3, 3], model[fl, :3, 3] * [-1, 1, 1], atol=1e-9)
    assert len(doc.undo_stack) == 2
    doc.undo()
    np.testing.assert_array_equal(doc.pose.rotation[right], sk.rest_rotation[right])


def test_skeleton_with_moved_joint_keeps_children():
    sk = chain_skeleton(4)
    new = skeleton_with_moved_joint(sk, 1, [0.5, 1.2, 0.0])
    heads = new.bind_matrices[:, :3, 3]
    np.testing.assert_allclose(heads[1], [0.5, 1.2, 0.0])
    np.testing.assert_allclose(heads[[0, 2, 3]], sk.bind_matrices[[0, 2, 3], :3, 3])
    # bind matrices agree with the forward kinematics of the new rest pose
    np.testing.assert_allclose(new.forward(new.rest_local_matrices()), new.bind_matrices,
                               atol=1e-12)


def test_rest_edit_undo_restores_skeleton_and_weights(doc):
    before = doc.rest_state()
    new = skeleton_with_moved_joint(doc.skeleton, 1, [0.2, 1.4, 0.0])
    from rigedit.model import compute_weights

    idx, w = compute_weights(doc.rig.vertices, new)
    w_before = doc.rig.binding.weights.copy()
    doc.push_rest_edit("Move j1", before, doc.make_rest_state(new, idx, w))
    assert doc.skeleton is new and doc.pose.skeleton is new
    assert not np.array_equal(doc.rig.binding.weights, w_before)
    doc.undo()
    assert doc.skeleton is before[0]
    np.testing.assert_array_equal(doc.rig.binding.weights, w_before)
    doc.redo()
    assert doc.skeleton is new


def test_amend_folds_a_command_into_the_last_step():
    from rigedit.editor.document import Command, UndoStack

    log = []
    stack = UndoStack()
    stack.push(Command("a", lambda: log.append("do a"), lambda: log.append("undo a")))
    stack.amend(Command("b", lambda: log.append("do b"), lambda: log.append("undo b")))
    assert len(stack) == 1 and stack.undo_label == "a + b"
    stack.undo()
    assert log == ["do a", "do b", "undo b", "undo a"]
    stack.redo()
    assert log[-2:] == ["do a", "do b"]
