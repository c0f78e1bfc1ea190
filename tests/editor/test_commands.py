"""The editor's commands on a small rig without a display: keys, clips, the auto-key, time and
sampling, recomputed weights, opening and saving."""
import numpy as np
import pytest

from builders import cylinder_rig
from rigedit.editor import commands as cmd
from rigedit.editor import events as ev
from rigedit.editor.document import Document


@pytest.fixture
def doc():
    return Document(cylinder_rig())   # clip "bend": j1 turns 60 degrees about z at 0.5 s


def test_set_time_samples_the_current_clip_unless_a_drag_holds_the_pose(doc):
    assert doc.current_clip == "bend"
    doc.set_time(0.5)
    np.testing.assert_allclose(doc.pose.get_euler("j1", degrees=True), [0, 0, 60], atol=1e-6)
    doc.begin_drag()
    doc.drag_euler("j2", [10, 0, 0])
    doc.set_time(0.0)   # playback during a drag does not fight it
    np.testing.assert_allclose(doc.pose.get_euler("j1", degrees=True), [0, 0, 60], atol=1e-6)
    doc.end_drag("Rotate j2")
    assert doc.undo_stack.undo_label == "Rotate j2" and len(doc.undo_stack) == 1
    doc.set_time(0.25, sample=False)
    np.testing.assert_allclose(doc.pose.get_euler("j2", degrees=True), [10, 0, 0], atol=1e-6)
    assert doc.sample(0.25).get_euler("j1", degrees=True)[2] == pytest.approx(30, abs=1e-6)
    doc.set_current_clip(None)
    assert doc.sample() is None


def test_delete_and_move_keys_with_undo(doc):
    assert cmd.key_near(doc, ["j1"], t=0.51) == pytest.approx(0.5)
    assert cmd.key_near(doc, ["j1"], t=0.6) is None
    assert cmd.delete_key(doc, ["j1"], t=0.6) == 0 and len(doc.undo_stack) == 0
    assert cmd.delete_key(doc, [1], t=0.51) == 1   # joints by index too
    np.testing.assert_allclose(doc.clip.key_times("j1"), [0, 1])
    assert cmd.move_keys(doc, {1.0: 5.0}) == 0     # clamped to the clip's end: stays
    np.testing.assert_allclose(doc.clip.key_times("j1"), [0, 1])
    assert len(doc.undo_stack) == 1                 # nothing moved: no step
    cmd.move_keys(doc, {1.0: 0.75})
    np.testing.assert_allclose(doc.clip.key_times("j1"), [0, 0.75])
    assert doc.undo_stack.undo_label == "Move key 1.00s -> 0.75s"
    doc.undo()
    doc.undo()
    np.testing.assert_allclose(doc.clip.key_times("j1"), [0, 0.5, 1])


def test_copy_paste_and_interpolation(doc):
    data = cmd.copy_keys(doc, ["j1"], t=0.5)
    assert cmd.paste_keys(doc, data, t=0.9) == 1
    np.testing.assert_allclose(doc.clip.sample(0.9).rotation[1], doc.clip.sample(0.5).rotation[1])
    assert cmd.set_interpolation(doc, "catmull_rom", "j1") == 1
    assert doc.clip.tracks[("j1", "rotation")].interpolation == "catmull_rom"
    with pytest.raises(ValueError):
        cmd.set_interpolation(doc, "no such mode", "j1")
    doc.undo()
    assert doc.clip.tracks[("j1", "rotation")].interpolation == "slerp"


def test_clip_commands_with_undo_and_refused_names(doc):
    heard = []
    doc.listen(heard.append)
    assert cmd.new_clip(doc, "walk", duration=3.0) == "walk" and doc.current_clip == "walk"
    assert heard[0] == ev.ClipChanged("walk")
    assert cmd.new_clip(doc, "Walk") == "Walk 2"     # names are unique ignoring case
    assert cmd.rename_clip(doc, "stride") == "stride"
    assert set(doc.clips) == {"bend", "walk", "stride"} and doc.clip.name == "stride"
    with pytest.raises(ValueError):
        cmd.rename_clip(doc, "BEND")                 # taken (ignoring case)
    with pytest.raises(ValueError):
        cmd.rename_clip(doc, "a/b")                  # not a path
    copy = cmd.duplicate_clip(doc)
    assert copy == "stride copy" and doc.clips[copy] is not doc.clips["stride"]
    assert cmd.delete_clip(doc) == copy and doc.current_clip == "bend"
    assert cmd.set_duration(doc, 2.5) and doc.clip.duration == 2.5
    assert not cmd.set_duration(doc, 2.5)
    steps = len(doc.undo_stack)
    assert steps == 6
    for _ in range(steps):
        doc.undo()
    assert set(doc.clips) == {"bend"} and doc.clips["bend"].duration == 1.0


def test_auto_key_folds_the_key_into_the_pose_edit(doc):
    doc.auto_key.enabled = True
    doc.set_time(0.25)
    doc.set_joint_euler("j2", [0, 0, 20])
    assert doc.undo_stack.undo_label == "Rotate j2 + auto-key j2"
    assert 0.25 in doc.clip.key_times("j2") and len(doc.undo_stack) == 1
    doc.undo()
    assert len(doc.clip.key_times("j2")) == 0
    cmd.set_key(doc, ["j1"])        # a clip edit of its own: not answered with more keys
    assert doc.undo_stack.undo_label == "Key j1 at 0.25s"
    doc.set_mode("edit")
    doc.set_joint_euler("j2", [0, 0, 20])   # edit mode: no auto-key
    assert len(doc.clip.key_times("j2")) == 0
    doc.set_mode("pose")
    doc.auto_key.enabled = False
    doc.set_joint_euler("j2", [0, 0, 30])
    assert len(doc.clip.key_times("j2")) == 0


def test_recompute_weights_reports_progress_and_is_one_undo_step(doc):
    from rigedit.binding import compute_weights
    from rigedit.model import SkinBinding

    rig, b0 = doc.rig, doc.rig.binding
    calls = []
    message = cmd.recompute_weights(doc, "idw", progress=lambda f, stage: calls.append(
        (f, stage)))
    assert message == f"Recomputed weights for {len(rig.vertices):,} vertices"
    assert doc.undo_stack.undo_label == "Recompute weights"
    assert calls and calls[-1] == (1.0, "idw")
    assert all(b >= a for (a, _), (b, _) in zip(calls, calls[1:]))
    indices, weights = compute_weights(rig.vertices, rig.skeleton, "idw", faces=rig.faces)
    assert doc.rig.binding is not b0
    expected = SkinBinding(rig.vertices, indices, weights, len(rig.skeleton))
    np.testing.assert_array_equal(doc.rig.binding.indices, expected.indices)
    np.testing.assert_array_equal(doc.rig.binding.weights, expected.weights)
    doc.undo()
    assert doc.rig.binding is b0


def test_recomputed_weights_for_a_replaced_rig_are_dropped(doc):
    job = cmd.RecomputeWeights(doc)
    assert job.method == "heat"     # a mesh with faces
    result = job.compute()
    doc.set_rig(cylinder_rig(with_clip=False))
    message, applied = job.apply(result)
    assert not applied and "another rig was opened" in message and len(doc.undo_stack) == 0


def test_open_replaces_the_rig_and_samples_its_first_clip(tmp_path):
    doc = Document(cylinder_rig(with_clip=False))
    heard = []
    doc.listen(heard.append)
    with pytest.raises(ValueError, match="no folder"):
        cmd.save_rig_folder(doc)
    cmd.save_rig_folder(doc, tmp_path / "cyl")
    rig = cmd.open_rig(doc, "quadruped")
    assert doc.rig is rig and heard[-1] == ev.RigReplaced() and len(doc.undo_stack) == 0
    assert doc.current_clip == "head_nod"
    assert doc.pose.allclose(rig.clips["head_nod"].sample(0.0))
    with pytest.raises(ValueError, match="bundled"):
        cmd.save_rig_folder(doc)    # the bundled character's own folder is read-only
    cmd.open_rig(doc, tmp_path / "cyl")
    assert len(doc.rig.vertices) == len(cylinder_rig().vertices) and doc.current_clip is None


def test_a_key_dragged_shows_where_it_is_and_is_one_undo_step(doc):
    drag = cmd.KeyDrag(doc, 0.5, ["j1"])
    drag.move(0.6)
    drag.move(0.8)
    np.testing.assert_allclose(doc.clip.key_times("j1"), [0, 0.8, 1])
    assert doc.time == 0.8 and len(doc.undo_stack) == 0   # shown, not yet a step
    np.testing.assert_allclose(doc.pose.get_euler("j1", degrees=True), [0, 0, 60], atol=1e-6)
    assert drag.end() == 1
    assert doc.undo_stack.undo_label == "Move key 0.50s -> 0.80s" and len(doc.undo_stack) == 1
    doc.undo()
    np.testing.assert_allclose(doc.clip.key_times("j1"), [0, 0.5, 1])
    back = cmd.KeyDrag(doc, 0.5)
    back.move(0.7)
    back.move(0.5)
    assert back.end() == 0 and doc.undo_stack.can_redo   # no step pushed (it clears redo)


def test_a_cancelled_recompute_changes_nothing(doc):
    from rigedit.progress import Cancelled

    def cancel(fraction, stage):
        raise Cancelled()

    b0 = doc.rig.binding
    with pytest.raises(Cancelled):
        cmd.recompute_weights(doc, "heat", progress=cancel)
    assert doc.rig.binding is b0 and len(doc.undo_stack) == 0


def test_a_pose_drag_solves_from_the_press_and_can_be_cancelled(doc):
    tip = doc.rig.joint_matrices(doc.pose)[2, :3, 3].copy()   # j2, the chain's end
    drag = cmd.PoseDrag(doc, "j2", chain_length=1)             # j1 turns
    assert doc.selection == 2 and doc.dragging
    drag.step(tip + [0.5, 0, 0])
    first = doc.pose_snapshot()
    drag.step(tip + [0.2, 0, 0])
    drag.step(tip + [0.5, 0, 0])    # the same target again gives the same pose: no drift
    np.testing.assert_allclose(doc.pose_snapshot(), first, atol=1e-12)
    assert not np.allclose(first, doc.rig.rest_pose().as_array())
    drag.cancel()
    assert not doc.dragging and len(doc.undo_stack) == 0
    assert doc.pose.allclose(doc.rig.rest_pose())
