"""The graph editor's commands (rigedit.editor.graph_commands): channels of the current clip as
curves, edits as one undo step each, a live drag, KeysChanged, continuity of rotations."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from builders import cylinder_rig
from rigedit.animation import Clip, Track
from rigedit.animation.curve import Curve
from rigedit.editor import events as ev
from rigedit.editor import graph_commands as gc
from rigedit.editor.document import Document

RZ = gc.ChannelId("j1", "rotation", 2)
TX = gc.ChannelId("j1", "translation", 0)


@pytest.fixture
def doc():
    return Document(cylinder_rig())   # clip "bend": j1 turns 60 degrees about z at 0.5 s


def euler_z(doc, t):
    doc.set_time(t)
    return doc.pose.get_euler("j1", degrees=True)[2]


def view(doc, cid):
    return next(v for v in gc.channels(doc, [cid.joint]) if v.id == cid)


def keys_events(doc):
    seen = []
    doc.listen(lambda e: seen.append(e) if isinstance(e, ev.KeysChanged) else None)
    return seen


def test_channels_of_a_joint(doc):
    views = gc.channels(doc, ["j1"])
    assert [v.label for v in views[:4]] == ["j1 translation X", "j1 translation Y",
                                            "j1 translation Z", "j1 rotation X"]
    rz = view(doc, RZ)
    assert not rz.bezier and rz.curve is not None and view(doc, TX).curve is None
    np.testing.assert_allclose(rz.curve.values, [0, 60, 0], atol=1e-9)
    np.testing.assert_allclose(rz.sample([0.25, 0.5]), [30, 60], atol=1e-6)
    assert len({v.colour for v in views}) == 9    # every channel its own colour
    doc.set_current_clip(None)
    assert gc.channels(doc, ["j1"]) == []


def test_edit_curves_is_one_undo_step_and_tells_the_views(doc):
    seen = keys_events(doc)
    curve = view(doc, RZ).curve.with_keys_moved([1], 0, 30)
    assert gc.edit_curves(doc, {RZ: curve}, "Move key") == 1
    assert len(doc.undo_stack) == 1 and doc.undo_stack.undo_label == "Move key"
    assert seen and view(doc, RZ).bezier
    assert euler_z(doc, 0.5) == pytest.approx(90, abs=1e-6)
    assert doc.clip.tracks[("j1", "rotation")].interpolation == "bezier"
    doc.undo()
    assert euler_z(doc, 0.5) == pytest.approx(60, abs=1e-6)
    assert doc.clip.tracks[("j1", "rotation")].interpolation != "bezier"
    doc.redo()
    assert euler_z(doc, 0.5) == pytest.approx(90, abs=1e-6)
    # the same curves again: no step
    assert gc.edit_curves(doc, {RZ: view(doc, RZ).curve}, "Nothing") == 0
    assert len(doc.undo_stack) == 1


def test_a_drag_is_one_undo_step_and_cancel_restores(doc):
    base = view(doc, RZ).curve
    seen = keys_events(doc)
    drag = gc.CurveDrag(doc, "Drag key")
    for dv in (5, 10, 20):
        drag.update({RZ: base.with_keys_moved([1], 0, dv)})
        assert euler_z(doc, 0.5) == pytest.approx(60 + dv, abs=1e-6)
    assert len(doc.undo_stack) == 0 and len(seen) == 3   # the views follow the drag live
    assert drag.finish() is True and len(doc.undo_stack) == 1
    assert euler_z(doc, 0.5) == pytest.approx(80, abs=1e-6)
    doc.undo()
    assert euler_z(doc, 0.5) == pytest.approx(60, abs=1e-6)
    drag = gc.CurveDrag(doc, "Drag again")
    drag.update({RZ: base.with_keys_moved([1], 0, 40)})
    drag.cancel()
    assert euler_z(doc, 0.5) == pytest.approx(60, abs=1e-6)
    assert doc.undo_stack.redo_label == "Drag key"    # the cancelled drag recorded nothing
    assert gc.CurveDrag(doc, "Still").finish() is False


def test_moving_a_key_past_its_neighbour_stops_before_it(doc):
    curve = view(doc, RZ).curve.with_keys_moved([1], 2.0, 0)
    gc.edit_curves(doc, {RZ: curve}, "Move")
    times = view(doc, RZ).curve.times
    assert np.all(np.diff(times) > 0) and times[1] < 1.0


def test_insert_delete_and_per_key_settings(doc):
    assert gc.insert_keys(doc, [RZ, TX], 0.25) == 2
    rz, tx = view(doc, RZ), view(doc, TX)
    assert len(rz.curve) == 4 and rz.curve.values[1] == pytest.approx(30, abs=1e-6)
    rest = doc.skeleton.rest_translation[doc.skeleton.joint_index("j1")]
    assert tx.curve.values[0] == pytest.approx(rest[0])
    assert gc.set_interpolation(doc, {RZ: [0]}, "constant") == 1
    assert euler_z(doc, 0.2) == pytest.approx(0, abs=1e-9)
    assert gc.set_handle_type(doc, {RZ: [1]}, "vector") == 1
    assert view(doc, RZ).curve.right_type[1] == "vector"
    assert gc.set_easing(doc, {RZ: [2]}, "ease_in") == 1
    assert view(doc, RZ).curve.left_type[2] == "free"
    assert gc.delete_keys(doc, {RZ: [1]}) == 1 and len(view(doc, RZ).curve) == 3
    n = len(doc.undo_stack)
    assert n == 5
    states = []
    for _ in range(n):   # each step undoes to a different clip, then redoes to the same
        states.append([float(euler_z(doc, t)) for t in (0.1, 0.2, 0.3, 0.6)])
        doc.undo()
    assert doc.clip.tracks[("j1", "rotation")].interpolation != "bezier"
    assert ("j1", "translation") not in doc.clip.tracks
    for state in reversed(states):
        doc.redo()
        np.testing.assert_allclose([euler_z(doc, t) for t in (0.1, 0.2, 0.3, 0.6)], state,
                                   atol=1e-9)
    assert len(view(doc, RZ).curve) == 3 and view(doc, RZ).curve.left_type[1] == "free"


def test_deleting_every_key_of_a_channel_removes_its_track(doc):
    gc.insert_keys(doc, [TX], 0.5)
    gc.edit_curves(doc, {TX: Curve([0.25, 0.75], [1.0, 2.0], "linear")}, "Key")
    assert gc.delete_keys(doc, {TX: [0, 1]}) == 2
    # an axis without keys holds the value it had where the others' keys start (0.5 s)
    assert ("j1", "translation") in doc.clip.tracks
    assert len(view(doc, TX).curve) == 1 and view(doc, TX).curve.values[0] == 1.5
    axes = [gc.ChannelId("j1", "translation", a) for a in range(3)]
    assert gc.delete_keys(doc, {cid: [0] for cid in axes}) == 3
    assert ("j1", "translation") not in doc.clip.tracks


def test_a_720_degree_spin_shows_a_monotonic_euler_curve(doc):
    times = np.arange(9) * 0.25
    quats = Rotation.from_rotvec(np.radians(90.0 * np.arange(9))[:, None] * [0, 0, 1]).as_quat()
    clip = Clip("spin", doc.skeleton, {("j1", "rotation"): Track("rotation", times, quats)})
    doc.clips["spin"] = clip
    doc.set_current_clip("spin")
    rz = view(doc, RZ)
    np.testing.assert_allclose(rz.curve.values, 90.0 * np.arange(9), atol=1e-6)
    assert np.all(np.diff(rz.sample(np.linspace(0, 2, 81))) > 0)
    # once bezier (an edit of another axis converts the track), it still spins 720 degrees
    rx = gc.ChannelId("j1", "rotation", 0)
    gc.edit_curves(doc, {rx: view(doc, rx).curve.with_keys_moved([0], 0, 0.0)}, "Touch")
    rz = view(doc, RZ)
    assert rz.bezier and np.all(np.diff(rz.curve.sample(np.linspace(0, 2, 81))) > 0)
    assert euler_z(doc, 1.125) % 360 == pytest.approx(45, abs=1e-6)


def test_whole_clip_interpolation_converts_a_bezier_track_back(doc):
    curve = view(doc, RZ).curve.with_keys_moved([1], 0, 30)
    gc.edit_curves(doc, {RZ: curve}, "Move")
    assert doc.clip.set_interpolation("slerp") == 1
    track = doc.clip.tracks[("j1", "rotation")]
    assert track.interpolation == "slerp" and track.curves is None
    assert euler_z(doc, 0.5) == pytest.approx(90, abs=1e-6)
