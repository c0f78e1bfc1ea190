"""Adversarial graph editor edits (rigedit.editor.graph_commands): keys of several channels
moved together past a neighbour, a scale by exactly 1, selections naming keys a curve no
longer has, and undo restoring the clip bitwise after every kind of edit."""
import numpy as np
import pytest

from builders import cylinder_rig
from rigedit.animation.curve import MIN_GAP, Curve
from rigedit.editor import graph_commands as gc
from rigedit.editor.document import Document

RX = gc.ChannelId("j1", "rotation", 0)
RY = gc.ChannelId("j1", "rotation", 1)
RZ = gc.ChannelId("j1", "rotation", 2)
TX = gc.ChannelId("j1", "translation", 0)


@pytest.fixture
def doc():
    return Document(cylinder_rig())   # clip "bend": j1 turns 60 degrees about z at 0.5 s


def curve_of(doc, cid):
    return gc.channel_curve(doc.clip, cid)


def snapshot(doc):
    """Every track's fields as bytes and names: equal only when bitwise equal."""
    out = {}
    for key, tr in doc.clip.tracks.items():
        curves = None if tr.curves is None else tuple(
            (c.times.tobytes(), c.values.tobytes(), c.left.tobytes(), c.right.tobytes(),
             tuple(c.interpolation), tuple(c.left_type), tuple(c.right_type))
            for c in tr.curves)
        out[key] = (tr.interpolation, tr.times.tobytes(), tr.values.tobytes(), curves,
                    tr.euler_order, None if tr.tangents is None else tr.tangents.tobytes())
    return out, doc.clip.duration


def test_keys_of_two_channels_move_together_past_a_neighbour_of_one(doc):
    # X has keys at 0, 0.5 and 0.6; Y and Z at 0, 0.5 and 1: the keys at 0.5 are one key
    # of the track (the timeline shows one)
    gc.edit_curves(doc, {RX: Curve([0, 0.5, 0.6], [0, 10, 20]),
                         RY: Curve([0, 0.5, 1.0], [0, 5, 0]),
                         RZ: Curve([0, 0.5, 1.0], [0, 60, 0])}, "Keys")
    before = len(doc.clip.tracks[("j1", "rotation")].times)
    base = {c: (curve_of(doc, c), [1]) for c in (RX, RY, RZ)}
    # clamped one curve at a time, the X key stops before 0.6 and the Z key goes on to 0.8
    alone = [c.with_keys_moved(i, 0.3, 0.0).times[1] for c, i in base.values()]
    assert alone[0] != alone[2]
    moved = gc.moved_keys(base, 0.3, 5.0)
    assert moved[RX].times[1] == moved[RZ].times[1] == pytest.approx(0.6 - MIN_GAP)
    assert moved[RX].values[1] == 15.0 and moved[RZ].values[1] == 65.0
    gc.edit_curves(doc, moved, "Move")
    assert len(doc.clip.tracks[("j1", "rotation")].times) == before   # still one key


def test_a_scale_by_exactly_one_changes_nothing(doc):
    gc.edit_curves(doc, {RZ: Curve([0, 0.1, 0.3, 0.7, 1.3], [0, 60, 30, 45, 0],
                                   left_type="free", right_type="free")}, "Keys")
    steps = len(doc.undo_stack)
    base = snapshot(doc)
    drag = gc.CurveDrag(doc, "Scale")
    for pivot in (0.7, 0.45, 1.0 / 3):   # the time cursor anywhere: x + (x - p) * 0
        curve = curve_of(doc, RZ)
        scaled = curve.scaled([1, 2, 3], pivot, 1.0, 0.0, 1.0)
        assert scaled == curve                      # bitwise (was an ulp off)
        drag.update({RZ: scaled})
    assert drag.finish() is False and len(doc.undo_stack) == steps   # no step for nothing
    assert snapshot(doc) == base


def test_a_selection_of_keys_the_curve_no_longer_has_is_ignored(doc):
    curve = curve_of(doc, RZ)                       # 3 keys
    # indices 3 and 7 do not exist (a selection from before an undo), -1 is not "the last"
    assert gc.delete_keys(doc, {RZ: [1, 3, 7, -1]}) == 1
    np.testing.assert_array_equal(curve_of(doc, RZ).times, np.delete(curve.times, 1))
    assert gc.set_interpolation(doc, {RZ: [5, -2]}, "constant") == 0
    assert gc.set_handle_type(doc, {RZ: [0, 0, 9]}, "vector") == 1
    assert curve_of(doc, RZ).left_type[0] == "vector" and curve_of(doc, RZ).left_type[1] != "vector"


def test_undo_restores_every_edit_bitwise_and_redo_replays_it(doc):
    def curve(cid):
        return curve_of(doc, cid)

    edits = [
        lambda: gc.edit_curves(doc, {RZ: curve(RZ).with_keys_moved([1], 0.1, 30)}, "Move"),
        lambda: gc.insert_keys(doc, [RZ, RX, TX], 0.3),
        lambda: gc.set_interpolation(doc, {RZ: [0]}, "constant"),
        lambda: gc.set_handle_type(doc, {RX: [0, 1]}, "vector"),
        lambda: gc.set_easing(doc, {RZ: [1]}, "ease_in_out"),
        lambda: gc.edit_curves(doc, {RX: curve(RX).with_handle(1, "right", (9.0, 99.0))},
                               "Handle"),
        lambda: gc.edit_curves(doc, {RX: curve(RX).scaled([0, 1, 2], 0.3, 0.0, 0, 1)}, "S"),
        lambda: gc.delete_keys(doc, {RZ: [0, 1, 2, 3]}),
        lambda: gc.delete_keys(doc, {RX: list(range(len(curve(RX))))}),
    ]
    states = [snapshot(doc)]
    for edit in edits:
        edit()
        states.append(snapshot(doc))
        assert states[-1] != states[-2]              # each edit changed something ...
    assert len(doc.undo_stack) == len(edits)         # ... as one step
    for i in range(len(edits) - 1, -1, -1):
        doc.undo()
        assert snapshot(doc) == states[i]
    for i in range(1, len(edits) + 1):
        doc.redo()
        assert snapshot(doc) == states[i]
