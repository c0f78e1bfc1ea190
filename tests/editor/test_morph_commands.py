"""The document's morph weights: shown from the clip, set and keyed as undo steps."""
import numpy as np
import pytest

from builders import cylinder_rig
from morph_builders import add_targets
from rigedit.animation.morph_track import WeightTrack
from rigedit.editor import commands as cmd
from rigedit.editor import events as ev
from rigedit.editor.document import Document


@pytest.fixture
def doc():
    rig = add_targets(cylinder_rig())
    d = Document(rig)
    d.events = []
    d.listen(d.events.append)
    return d


def _morph_events(d):
    return [e for e in d.events if isinstance(e, ev.MorphChanged)]


def test_set_weight_moves_the_mesh_is_one_undo_step_and_is_announced(doc):
    pose = doc.pose
    rest = doc.rig.skin(pose, morph_weights=[0, 0])
    before = doc.rig.binding.skin(_palette(doc)).copy()
    assert cmd.set_weight(doc, "bulge", 1.0)
    assert doc.morph.weight("bulge") == 1.0
    after = doc.rig.binding.skin(_palette(doc)).copy()
    assert np.abs(after - before).max() > 0.05                    # the shape shows
    np.testing.assert_allclose(doc.rig.skin(pose, morph_weights={"bulge": 1.0}), after,
                               atol=1e-6)
    kinds = [type(e) for e in doc.events]
    assert ev.MorphChanged in kinds and kinds.index(ev.PoseChanged) > kinds.index(
        ev.MorphChanged)                                          # views redraw after
    assert _morph_events(doc)[-1].weights == (1.0, 0.0)
    assert doc.undo_stack.undo_label == "Set bulge 1.00"
    doc.undo()
    assert doc.morph.weight("bulge") == 0.0
    np.testing.assert_allclose(doc.rig.binding.skin(_palette(doc)), rest, atol=1e-6)
    doc.redo()
    assert doc.morph.weight("bulge") == 1.0
    assert not cmd.set_weight(doc, "bulge", 1.0)                  # no change, no step
    with pytest.raises(KeyError):
        cmd.set_weight(doc, "nose", 1.0)


def _palette(doc):
    from rigedit.model.kinematics import skinning_matrices
    return skinning_matrices(doc.skeleton, doc.rig.joint_matrices(doc.pose))


def test_a_slider_drag_is_one_undo_step(doc):
    n = len(doc.undo_stack)
    drag = cmd.WeightDrag(doc, "squash")
    for w in np.linspace(0, 0.8, 9):
        drag.step(w)
    assert doc.morph.weight("squash") == pytest.approx(0.8)
    assert len(doc.undo_stack) == n                                # nothing until release
    assert drag.end()
    assert len(doc.undo_stack) == n + 1
    doc.undo()
    assert doc.morph.weight("squash") == 0.0
    back = cmd.WeightDrag(doc, "squash")
    back.step(0.3)
    back.step(0.0)
    assert not back.end()                                           # back where it was


def test_key_weight_keys_the_current_clip_and_the_weights_follow_time(doc):
    clip = doc.clip
    cmd.set_weight(doc, "bulge", 0.0)
    doc.set_time(0.0)
    cmd.key_weight(doc, "bulge", weight=0.0)
    doc.set_time(1.0)
    cmd.set_weight(doc, "bulge", 1.0)
    cmd.key_weight(doc, "bulge")
    assert doc.undo_stack.undo_label == "Key bulge at 1.00s"
    assert list(clip.morph_tracks["bulge"].times) == [0.0, 1.0]
    assert 1.0 in clip.key_times()                                 # the timeline's row
    doc.set_time(0.5)
    assert doc.morph.weight("bulge") == pytest.approx(0.5)         # sampled with the clip
    assert _morph_events(doc)[-1].weights[0] == pytest.approx(0.5)
    doc.undo()                                                     # the key at 1.0 goes
    assert list(clip.morph_tracks["bulge"].times) == [0.0]
    assert cmd.delete_weight_key(doc, "bulge", t=0.0) == 1
    assert "bulge" not in clip.morph_tracks
    doc.undo()
    assert "bulge" in clip.morph_tracks


def test_an_unkeyed_weight_lasts_until_the_time_changes(doc):
    doc.clip.set_morph_key("squash", 0.0, 0.25)
    doc.set_time(0.0)
    cmd.set_weight(doc, "squash", 0.9)
    cmd.set_weight(doc, "bulge", 0.4)                              # no track: default after
    doc.set_time(0.5)
    np.testing.assert_allclose(doc.morph.weights, [0.0, 0.25])


def test_a_document_without_a_clip_gets_one_for_a_weight_key():
    rig = add_targets(cylinder_rig(with_clip=False))
    d = Document(rig)
    cmd.key_weight(d, "squash", weight=0.5)
    assert d.clip is not None and d.clip.morph_tracks["squash"].values[0] == 0.5


def test_auto_key_keys_a_set_weight_in_the_same_step(doc):
    doc.auto_key.enabled = True
    doc.set_time(0.5)
    n = len(doc.undo_stack)
    cmd.set_weight(doc, "bulge", 0.7)
    assert len(doc.undo_stack) == n + 1
    assert doc.clip.morph_tracks["bulge"].sample(0.5) == pytest.approx(0.7)
    doc.undo()
    assert "bulge" not in doc.clip.morph_tracks and doc.morph.weight("bulge") == 0.0


def test_a_rest_edit_keeps_the_weights_shown(doc):
    cmd.set_weight(doc, "bulge", 0.6)
    b = doc.rig.binding
    doc.set_weights(b.indices, b.weights)                          # a new binding
    assert doc.rig.binding is not b
    assert doc.morph.weight("bulge") == 0.6
    doc.undo()
    assert doc.rig.binding is b and doc.morph.weight("bulge") == 0.6


def test_a_rig_without_targets_has_no_weights():
    d = Document(cylinder_rig())
    assert d.morph.names == () and len(d.morph.weights) == 0
    d.set_time(0.5)
    with pytest.raises(KeyError):
        cmd.set_weight(d, "bulge", 1.0)
    assert ev.from_name("morph", weights=(1.0,)) == ev.MorphChanged((1.0,))
