"""The document's typed events and its listeners of both kinds (typed objects, old strings)."""
import pytest

from builders import cylinder_rig
from rigedit.editor import events as ev
from rigedit.editor.document import Document


def test_listeners_of_both_kinds_are_called_in_registration_order():
    heard = []
    listeners = ev.Listeners()
    listeners.subscribe(lambda event, **info: heard.append(("old", event, info)))
    typed = listeners.listen(lambda e: heard.append(("new", e)))
    listeners.emit(ev.SelectionChanged(2))
    listeners.emit(ev.KeysChanged("walk"))
    listeners.remove(typed)
    listeners.emit(ev.UndoChanged("Rotate j1", "", True))
    assert heard == [("old", "selection", {"joint": 2}), ("new", ev.SelectionChanged(2)),
                     ("old", "clip", {"name": "walk"}), ("new", ev.KeysChanged("walk")),
                     ("old", "undo", {})]


def test_old_names_map_to_typed_events():
    assert ev.from_name("clip", name="walk") == ev.ClipChanged("walk")
    assert ev.from_name("pose", joints=[3, 1]) == ev.PoseChanged((3, 1))
    assert ev.from_name("time", time=0.5) == ev.TimeChanged(0.5)
    assert ev.from_name("rig") == ev.RigReplaced()
    assert isinstance(ev.KeysChanged("a"), ev.ClipChanged)   # a clip view hears key edits
    assert ev.KeysChanged("a") != ev.ClipChanged("a")
    with pytest.raises(ValueError, match="unknown document event 'poses'"):
        ev.from_name("poses")
    with pytest.raises(AttributeError):
        ev.TimeChanged(1.0).time = 2.0   # frozen


def test_a_string_emitted_the_old_way_reaches_typed_listeners():
    doc = Document(cylinder_rig())
    heard = []
    doc.listen(heard.append)
    doc.emit("clip", name="bend")
    doc.set_pose(doc.pose, joints=[1])
    assert heard == [ev.ClipChanged("bend"), ev.PoseChanged((1,))]


def test_rest_edits_say_whether_the_skeleton_or_only_the_weights_changed():
    from rigedit.editor.deform import set_joint_deform

    doc = Document(cylinder_rig())
    heard = []
    doc.listen(heard.append)
    b = doc.rig.binding
    doc.set_weights(b.indices, b.weights[:, ::-1].copy())
    assert heard[:2] == [ev.WeightsChanged(), ev.PoseChanged()]
    heard.clear()
    assert set_joint_deform(doc, "j2", False)
    assert heard[:2] == [ev.RestChanged(weights=False), ev.PoseChanged()]
    assert not doc.skeleton.deform[2] and doc.undo_stack.undo_label == "No deform j2"
    assert not set_joint_deform(doc, "j2", False)   # already so: no step
    doc.undo()
    assert doc.skeleton.deform[2]


def test_undo_emitted_by_name_carries_the_history_state():
    doc = Document(cylinder_rig())
    doc.set_joint_euler(1, [0, 0, 10])
    heard = []
    doc.listen(heard.append)
    doc.emit("undo")
    assert heard == [ev.UndoChanged("Rotate j1", "", True)]
