"""The drag controller on its own: a real Document, and the view parts it is handed (scene,
gizmos, axis arrows) as small stand-ins recording what it asks of them. No window, no Qt."""
from __future__ import annotations

import numpy as np
import pytest

from rigedit.editor.document import Document
from rigedit.editor.drag import DragController, DragSettings, constrain
from rigedit.ui.fallback import demo_rig


class Scene:
    """What the controller reads of a RigScene: joint positions following the document's
    pose, and the bones' points (the edit-mode preview)."""

    def __init__(self, document):
        self.document = document
        self.bones = _Points(len(document.skeleton))
        document.subscribe(self._on_document)
        self._on_document("pose")

    def _on_document(self, event, **info):
        if event == "pose":
            self.joint_positions = self.document.rig.joint_matrices(
                self.document.pose)[:, :3, 3].copy()


class _Points:
    def __init__(self, n):
        self.points = np.zeros((n, 3))
        self.modified = 0

    def Modified(self):  # noqa: N802 - VTK's name
        self.modified += 1


class Gizmos:
    def __init__(self, positions):
        self.positions = np.array(positions, dtype=float)

    def center(self, j):
        return self.positions[j].copy()

    def set_center(self, j, p):
        self.positions[j] = p


class Axes:
    position = None

    def set_position(self, p):
        self.position = np.array(p)


@pytest.fixture
def parts():
    doc = Document(demo_rig())
    scene = Scene(doc)
    gizmos = Gizmos(scene.joint_positions)
    moved, messages = [], []

    def move_rest(j, head):
        moved.append((j, np.array(head)))
        return parts.accept

    settings = DragSettings()
    drag = DragController(doc, scene, gizmos, Axes(), settings, move_rest, messages.append,
                          lambda: None)
    parts = type("Parts", (), dict(doc=doc, scene=scene, gizmos=gizmos, drag=drag,
                                   settings=settings, moved=moved, messages=messages,
                                   accept="job"))
    return parts


def _joint(doc, name):
    return doc.skeleton.index[name]


def test_pose_drag_is_one_undo_step_and_the_sphere_snaps_onto_the_joint(parts):
    doc, drag, gizmos = parts.doc, parts.drag, parts.gizmos
    j = _joint(doc, "front_shin_L")
    rest = doc.pose_snapshot()
    start = gizmos.center(j)
    drag.start(j)
    assert drag.active and doc.selection == j and doc.dragging
    for k in range(1, 4):  # each move starts from the pose at the press, not the last one
        target = start + np.array([0.0, 0.05 * k, 0.1 * k])
        gizmos.set_center(j, target)
        drag.move(j, target)
    assert len(doc.undo_stack) == 0  # nothing recorded mid-drag
    drag.end(j)
    assert not drag.active and not doc.dragging
    assert len(doc.undo_stack) == 1 and doc.undo_stack.undo_label == "Drag front_shin_L"
    assert not np.array_equal(doc.pose_snapshot(), rest)
    np.testing.assert_allclose(gizmos.center(j), parts.scene.joint_positions[j])
    assert parts.messages[-1] == "Posed front_shin_L"
    doc.undo()
    np.testing.assert_array_equal(doc.pose_snapshot(), rest)


def test_chain_length_one_turns_the_parent_only(parts):
    doc, drag, gizmos = parts.doc, parts.drag, parts.gizmos
    sk = doc.skeleton
    j = _joint(doc, "front_shin_L")
    parts.settings.chain_length = 1
    rest = doc.pose_snapshot()
    drag.start(j)
    drag.move(j, gizmos.center(j) + [0.0, 0.0, 0.2])
    drag.end(j)
    changed = np.flatnonzero(np.any(doc.pose_snapshot() != rest, axis=1))
    assert changed.tolist() == [sk.parents[j]]


def test_toolbar_axis_and_arrow_axis_constrain_a_root_drag(parts):
    doc, drag, gizmos = parts.doc, parts.drag, parts.gizmos
    sk = doc.skeleton
    parts.settings.axis = 1
    start = gizmos.center(0)
    drag.start(0)
    drag.move(0, start + np.array([0.4, 0.25, -0.3]))
    np.testing.assert_allclose(gizmos.center(0), start + [0.0, 0.25, 0.0])  # sphere on axis
    drag.end(0)
    np.testing.assert_allclose(doc.pose.translation[0] - sk.rest_translation[0],
                               [0.0, 0.25, 0.0], atol=1e-9)
    # an arrow handle's axis wins over the toolbar's, and drags the selected joint
    doc.select(0)
    drag.axis_start(2)
    drag.axis_move(2, gizmos.center(0) + np.array([0.3, 0.3, 0.1]))
    drag.axis_end(2)
    np.testing.assert_allclose(doc.pose.translation[0] - sk.rest_translation[0],
                               [0.0, 0.25, 0.1], atol=1e-9)
    assert len(doc.undo_stack) == 2


def test_edit_mode_previews_the_bone_and_hands_the_rest_move_over(parts):
    doc, drag, gizmos = parts.doc, parts.drag, parts.gizmos
    doc.mode = "edit"
    j = _joint(doc, "front_shin_L")
    rest = doc.pose_snapshot()
    target = gizmos.center(j) + [0.0, 0.05, 0.0]
    drag.start(j)
    drag.move(j, target)
    np.testing.assert_allclose(parts.scene.bones.points[j], target)  # the bone follows
    np.testing.assert_allclose(drag.axes.position, target)
    drag.end(j)
    assert len(parts.moved) == 1 and parts.moved[0][0] == j
    np.testing.assert_allclose(parts.moved[0][1], target)
    np.testing.assert_array_equal(doc.pose_snapshot(), rest)  # the pose is not edited
    assert len(doc.undo_stack) == 0


def test_edit_mode_refused_move_snaps_back_and_a_click_moves_nothing(parts):
    doc, drag, gizmos = parts.doc, parts.drag, parts.gizmos
    doc.mode = "edit"
    j = _joint(doc, "front_shin_L")
    home = gizmos.center(j)
    parts.accept = None  # another job runs: the rest move is refused
    drag.start(j)
    gizmos.set_center(j, home + [0.0, 0.1, 0.0])
    drag.move(j, home + [0.0, 0.1, 0.0])
    drag.end(j)
    np.testing.assert_allclose(gizmos.center(j), home)
    drag.start(j)  # a press and release without a move
    drag.end(j)
    assert len(parts.moved) == 1


def test_moves_of_another_joint_or_without_a_drag_are_ignored(parts):
    doc, drag = parts.doc, parts.drag
    rest = doc.pose_snapshot()
    drag.move(3, np.ones(3))
    drag.end(3)
    drag.start(3)
    drag.move(4, np.ones(3))
    np.testing.assert_array_equal(doc.pose_snapshot(), rest)
    drag.end(3)
    assert len(doc.undo_stack) == 0  # a drag that changed nothing leaves no step


def test_constrain_projects_onto_the_axis_line():
    start = np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(constrain(start, np.array([4.0, 5.0, 6.0]), 0), [4.0, 2.0, 3.0])
    np.testing.assert_allclose(constrain(start, np.array([4.0, 5.0, 6.0]), None), [4, 5, 6])
