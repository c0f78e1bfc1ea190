"""The graph editor dock on a real window under Xvfb, driven by real mouse events on its
canvas (QTest): select a key by clicking it, drag it in time and value, drag a handle, box
selection, undo, the shared time cursor, hidden channels; the clip's sampled values are
checked after each edit.

The rig is the bundled quadruped with a small clip of our own ("sway": a few keys far apart,
so a key can move without meeting its neighbour); the walk is used where dense keys matter.
"""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

pytestmark = [pytest.mark.ui]

from PyQt5 import QtCore, QtGui, QtWidgets  # noqa: E402
from PyQt5.QtTest import QTest  # noqa: E402

from rigedit.animation import Clip, Track  # noqa: E402
from rigedit.editor import events as ev  # noqa: E402
from rigedit.editor.graph_commands import ChannelId  # noqa: E402

from ui_window_fixture import editor_window  # noqa: E402

JOINT = "pelvis"
T_Y = ChannelId(JOINT, "translation", 1)
R_X = ChannelId(JOINT, "rotation", 0)
KEY_TIMES = [0.0, 0.3, 0.6, 1.0]
BOB = [0.0, 0.2, -0.1, 0.0]      # added to the rest height at KEY_TIMES


def _sway(rig):
    sk = rig.skeleton
    j = sk.index[JOINT]
    rest_t, rest_q = sk.rest_translation[j], Rotation.from_quat(sk.rest_rotation[j])
    tv = np.tile(rest_t, (len(KEY_TIMES), 1))
    tv[:, 1] += BOB
    q = [(rest_q * Rotation.from_euler("x", a, degrees=True)).as_quat() for a in (0, 20, 0)]
    tracks = {(JOINT, "translation"): Track("translation", KEY_TIMES, tv, "linear"),
              (JOINT, "rotation"): Track("rotation", [0.0, 0.5, 1.0], q)}
    return Clip("sway", sk, tracks, duration=1.0)


@pytest.fixture
def window(qtbot, rig_template):
    rig = rig_template
    saved = {n: c.state() for n, c in rig.clips.items()}
    rig.clips["sway"] = _sway(rig)
    try:
        with editor_window(qtbot, rig, size=(1200, 1000)) as w:
            d = w.document
            d.set_current_clip("sway")
            d.select(JOINT)
            w.graph_editor.dock.show()
            view = w.graph_editor.view
            qtbot.waitUntil(lambda: view.isVisible() and view.height() > 150, timeout=3000)
            yield w
    finally:
        del rig.clips["sway"]
        for n, c in rig.clips.items():
            c.restore(saved[n])


def _only(window, *shown):
    """Show only channels ``shown`` and frame them."""
    ge = window.graph_editor
    for c in ge.view.channels:
        if c.curve is not None:
            ge.channel_list.set_shown(c.id, c.id in shown)
    ge.view.frame_all()
    return ge.view


def _channel(view, cid):
    return next(c for c in view.channels if c.id == cid)


def _key_pos(view, cid, k):
    cv = _channel(view, cid).curve
    return QtCore.QPoint(int(round(float(view.transform.x_of(cv.times[k])))),
                         int(round(float(view.transform.y_of(cv.values[k])))))


def _height(window, t):
    """The pelvis's height the clip plays at ``t`` (what the 3D view shows there)."""
    d = window.document
    return d.clip.sample(t, out=d.rig.rest_pose()).translation[d.skeleton.index[JOINT], 1]


def _move(view, pos, modifiers=QtCore.Qt.NoModifier):
    """A mouse move with the left button held (QTest.mouseMove moves the X pointer, which
    under Xvfb arrives late or not at all; Qt delivers this event as it does a real one)."""
    e = QtGui.QMouseEvent(QtCore.QEvent.MouseMove, QtCore.QPointF(pos), QtCore.Qt.NoButton,
                          QtCore.Qt.LeftButton, modifiers)
    QtWidgets.QApplication.sendEvent(view, e)


def _drag(view, start, end, steps=6, modifiers=QtCore.Qt.NoModifier):
    QTest.mousePress(view, QtCore.Qt.LeftButton, modifiers, start)
    for s in range(1, steps + 1):
        _move(view, start + (end - start) * (s / steps), modifiers)
    QTest.mouseRelease(view, QtCore.Qt.LeftButton, modifiers, end)


def test_clicking_a_key_selects_it_and_shift_adds(window):
    view = _only(window, T_Y)
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, _key_pos(view, T_Y, 1))
    assert {k: v.tolist() for k, v in view.selected.items()} == {T_Y: [1]}
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.ShiftModifier,
                     _key_pos(view, T_Y, 2))
    assert view.selected[T_Y].tolist() == [1, 2]
    # a click on empty space clears
    empty = QtCore.QPoint(_key_pos(view, T_Y, 1).x() + 40, view.height() - 12)
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, empty)
    assert view.selected == {}


def test_dragging_a_key_moves_it_to_a_frame_in_time_and_by_the_mouse_in_value(window):
    d, view = window.document, _only(window, T_Y)
    fps = window.timeline.fps
    heard = []
    d.listen(heard.append)
    start = _key_pos(view, T_Y, 1)
    end = start + QtCore.QPoint(90, -23)
    _drag(view, start, end)
    tr = view.transform
    # the time moved by the mouse and landed on a frame; the value by the mouse exactly
    want_t = round((0.3 + 90 / tr.px_per_s) * fps) / fps
    want_v = d.skeleton.rest_translation[d.skeleton.index[JOINT], 1] + 0.2 + 23 / tr.px_per_unit
    cv = _channel(view, T_Y).curve
    assert cv.times[1] == pytest.approx(want_t, abs=1e-9)
    assert abs(want_t - 0.3) > 1.5 / fps            # it really moved
    assert _height(window, want_t) == pytest.approx(want_v, abs=1e-6)
    # the old place no longer plays the old key's height
    assert abs(_height(window, 0.3) - (want_v - 23 / tr.px_per_unit)) > 1e-3
    # one undo step; the 3D view's pose and the timeline heard the edit
    assert d.undo_stack.undo_label == "Move keys"
    assert any(isinstance(e, ev.KeysChanged) for e in heard)
    assert any(isinstance(e, ev.PoseChanged) for e in heard)
    # the timeline's row of the joint: the union of its curves' keys (X and Z keep 0.3)
    union = np.unique(np.concatenate([c.curve.times for c in view.channels
                                      if c.curve is not None]).round(9))
    assert want_t in union.tolist() and 0.3 in union.tolist()
    assert window.timeline.ruler.joint_keys.tolist() == pytest.approx(union.tolist())
    assert np.allclose(d.pose.translation, d.sample().translation)


def test_ctrl_frees_the_drag_from_frames(window):
    view = _only(window, T_Y)
    start = _key_pos(view, T_Y, 1)
    _drag(view, start, start + QtCore.QPoint(13, 0), modifiers=QtCore.Qt.ControlModifier)
    t = _channel(view, T_Y).curve.times[1]
    fps = window.timeline.fps
    assert t == pytest.approx(0.3 + 13 / view.transform.px_per_s, abs=1e-9)
    assert abs(t * fps - round(t * fps)) > 1e-3


def test_undo_restores_the_sampled_values(window):
    d, view = window.document, _only(window, T_Y)
    times = np.linspace(0, 1, 41)
    before = [_height(window, t) for t in times]
    start = _key_pos(view, T_Y, 2)
    _drag(view, start, start + QtCore.QPoint(-25, 30))
    after = [_height(window, t) for t in times]
    assert not np.allclose(before, after)
    window.undo()
    assert np.allclose([_height(window, t) for t in times], before, atol=1e-12)
    assert view.selected.get(T_Y) is not None   # the selection stays with the key


def test_dragging_a_handle_bends_the_curve_between_its_keys(window):
    d, view = window.document, _only(window, T_Y)
    ge = window.graph_editor
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, _key_pos(view, T_Y, 1))
    ge.set_interpolation("bezier")            # the tool row's Bezier: 0.3 -> 0.6 bends
    view.frame_all()
    cv = _channel(view, T_Y).curve
    mid = 0.45
    before_mid = _height(window, mid)
    keys_before = [_height(window, t) for t in KEY_TIMES]
    tr = view.transform
    handle = cv.right[1].copy()
    grab = QtCore.QPoint(int(round(float(tr.x_of(cv.right[1, 0])))),
                         int(round(float(tr.y_of(cv.right[1, 1])))))
    _drag(view, grab, grab + QtCore.QPoint(0, -60))    # up: the curve after key 1 rises
    cv = _channel(view, T_Y).curve
    assert cv.right_type[1] in ("aligned", "free")
    # the handle moved by the mouse's travel (grabbed anywhere on its dot)
    assert cv.right[1] == pytest.approx(handle + [0.0, 60 / tr.px_per_unit], abs=1e-9)
    assert _height(window, mid) > before_mid + 1e-3
    # the keys stay where they were
    assert [_height(window, t) for t in KEY_TIMES] == pytest.approx(keys_before, abs=1e-9)
    assert d.undo_stack.undo_label == "Move handle"


def test_box_selection_selects_the_keys_inside_and_shift_adds(window):
    view = _only(window, T_Y, R_X)
    a, b = _key_pos(view, T_Y, 1), _key_pos(view, T_Y, 2)
    top_left = QtCore.QPoint(a.x() - 8, min(a.y(), b.y()) - 8)
    bottom_right = QtCore.QPoint(b.x() + 8, max(a.y(), b.y()) + 8)
    _drag(view, top_left, bottom_right)
    inside = view.selected
    assert inside[T_Y].tolist() == [1, 2]
    # every selected key is inside the box, and every key inside is selected
    rect = QtCore.QRect(top_left, bottom_right)
    for c in view.visible_channels():
        index, xs, ys = view.visible_keys(c)
        want = [int(i) for i, x, y in zip(index, xs, ys) if rect.contains(int(x), int(y))]
        assert inside.get(c.id, np.zeros(0)).tolist() == want
    first = _key_pos(view, T_Y, 0)
    _drag(view, first - QtCore.QPoint(6, 6), first + QtCore.QPoint(6, 6),
          modifiers=QtCore.Qt.ShiftModifier)
    assert view.selected[T_Y].tolist() == [0, 1, 2]


def test_hidden_channels_are_neither_drawn_nor_hit(window):
    view = _only(window, T_Y, R_X)
    pos = _key_pos(view, T_Y, 1)
    colour = QtGui.QColor.fromRgbF(*_channel(view, T_Y).colour)

    def near_colour(image, p):
        c = image.pixelColor(p)
        return abs(c.red() - colour.red()) + abs(c.green() - colour.green()) + \
            abs(c.blue() - colour.blue()) < 90
    # a point on the curve between keys 1 and 2 (the line, not a key)
    cv = _channel(view, T_Y).curve
    t = 0.45
    on_line = QtCore.QPoint(int(round(float(view.transform.x_of(t)))),
                            int(round(float(view.transform.y_of(np.interp(t, cv.times,
                                                                          cv.values))))))
    assert near_colour(view.grab().toImage(), on_line)
    window.graph_editor.channel_list.set_shown(T_Y, False)
    assert T_Y in view.hidden
    assert not near_colour(view.grab().toImage(), on_line)
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, pos)
    assert T_Y not in view.selected
    window.graph_editor.channel_list.set_shown(T_Y, True)
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, pos)
    assert view.selected[T_Y].tolist() == [1]


def test_the_time_cursor_follows_the_document_and_the_ruler_sets_it(window):
    d, view = window.document, _only(window, T_Y)
    d.set_time(0.5)
    assert view.time == 0.5
    x = int(round(float(view.transform.x_of(0.5))))
    image = view.grab().toImage()
    red = image.pixelColor(x, view.height() // 2)
    assert red.red() > 180 and red.green() < 110
    # a click in the ruler area sets the document's time, on a frame
    fps = window.timeline.fps
    x2 = int(round(float(view.transform.x_of(0.8))))
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, QtCore.QPoint(x2, 8))
    want = round(float(view.transform.t_of(x2)) * fps) / fps
    assert d.time == pytest.approx(want)
    assert window.timeline.time == pytest.approx(want)


def test_delete_and_insert_keys_from_the_keyboard(window):
    d, view = window.document, _only(window, T_Y)
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, _key_pos(view, T_Y, 1))
    QTest.keyClick(view, QtCore.Qt.Key_Delete)
    assert _channel(view, T_Y).curve.times.tolist() == pytest.approx([0.0, 0.6, 1.0])
    h = _height(window, 0.3)
    d.set_time(0.3)
    QTest.keyClick(view, QtCore.Qt.Key_I)       # on the shown channel only
    cv = _channel(view, T_Y).curve
    assert 0.3 in cv.times.round(9).tolist()
    assert _height(window, 0.3) == pytest.approx(h)   # the key holds what played there
    assert len(_channel(view, R_X).curve.times) == 3   # hidden: not keyed
    window.undo()
    window.undo()
    assert _channel(view, T_Y).curve.times.tolist() == pytest.approx(KEY_TIMES)


def test_wheel_zooms_time_and_ctrl_wheel_zooms_values_about_the_mouse(window):
    view = _only(window, T_Y)
    tr = view.transform
    pos = QtCore.QPoint(view.width() // 2, view.height() // 2)
    t_under, span_t, span_v = float(tr.t_of(pos.x())), tr.t1 - tr.t0, tr.v1 - tr.v0

    def wheel(mods):
        e = QtGui.QWheelEvent(QtCore.QPointF(pos), QtCore.QPointF(view.mapToGlobal(pos)),
                              QtCore.QPoint(), QtCore.QPoint(0, 120), QtCore.Qt.NoButton,
                              mods, QtCore.Qt.NoScrollPhase, False)
        QtCore.QCoreApplication.sendEvent(view, e)
    wheel(QtCore.Qt.NoModifier)
    assert tr.t1 - tr.t0 < span_t * 0.95 and tr.v1 - tr.v0 == pytest.approx(span_v)
    assert float(tr.t_of(pos.x())) == pytest.approx(t_under)
    wheel(QtCore.Qt.ControlModifier)
    assert tr.v1 - tr.v0 < span_v * 0.95


def test_the_walk_draws_and_the_view_menu_shows_the_dock(window):
    d = window.document
    d.set_current_clip("walk")
    ge = window.graph_editor
    ge.dock.hide()
    act = next(a for m in window.menuBar().actions() for a in m.menu().actions()
               if a.text() == "Graph editor")
    act.trigger()
    assert ge.dock.isVisible()
    shown = [c for c in ge.view.visible_channels()]
    assert {c.id.channel for c in shown} == {"translation", "rotation"}
    assert all(len(c.curve.times) == len(d.clip.tracks[(JOINT, c.id.channel)].times)
               for c in shown)


def _click_button(window, text):
    from PyQt5 import QtWidgets as W
    b = next(b for b in window.graph_editor.dock.findChildren(W.QToolButton) if b.text() == text)
    QTest.mouseClick(b, QtCore.Qt.LeftButton)


def test_s_scales_the_selected_keys_about_the_time_cursor(window):
    d, view = window.document, _only(window, T_Y)
    d.set_time(0.0)
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, _key_pos(view, T_Y, 1))
    tr = view.transform
    x0, x_key = float(tr.x_of(0.0)), _key_pos(view, T_Y, 1).x()
    QTest.keyClick(view, QtCore.Qt.Key_S)
    # the mouse at 1.5 times the key's distance from the cursor: the key's time x1.5
    target = QtCore.QPoint(int(round(x0 + 1.5 * (x_key - x0))), _key_pos(view, T_Y, 1).y())
    e = QtGui.QMouseEvent(QtCore.QEvent.MouseMove, QtCore.QPointF(target), QtCore.Qt.NoButton,
                          QtCore.Qt.NoButton, QtCore.Qt.NoModifier)
    QtWidgets.QApplication.sendEvent(view, e)
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, target)
    cv = _channel(view, T_Y).curve
    assert cv.times.tolist() == pytest.approx([0.0, 0.45, 0.6, 1.0])
    assert d.undo_stack.undo_label == "Scale keys"
    assert _height(window, 0.45) == pytest.approx(_height(window, 0.0) + 0.2)
    # Esc cancels a scale: nothing changes
    QTest.keyClick(view, QtCore.Qt.Key_S)
    QtWidgets.QApplication.sendEvent(view, QtGui.QMouseEvent(
        QtCore.QEvent.MouseMove, QtCore.QPointF(target + QtCore.QPoint(40, 0)),
        QtCore.Qt.NoButton, QtCore.Qt.NoButton, QtCore.Qt.NoModifier))
    QTest.keyClick(view, QtCore.Qt.Key_Escape)
    assert _channel(view, T_Y).curve.times.tolist() == pytest.approx([0.0, 0.45, 0.6, 1.0])
    assert d.undo_stack.undo_label == "Scale keys"


def test_the_tool_row_sets_interpolation_and_easing_on_the_selected_key(window):
    view = _only(window, T_Y)
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, _key_pos(view, T_Y, 1))
    h1, h2 = _height(window, 0.3), _height(window, 0.6)
    linear_at = h1 + (h2 - h1) * 0.1            # a tenth into the segment 0.3 -> 0.6
    _click_button(window, "Ease out")           # the curve leaves key 1 flat
    eased = _height(window, 0.33)
    assert abs(eased - h1) < 0.5 * abs(linear_at - h1)
    assert _channel(view, T_Y).curve.interpolation[1] == "bezier"
    _click_button(window, "Constant")           # holds key 1's value until key 2
    assert _height(window, 0.59) == pytest.approx(h1)
    assert _height(window, 0.6) == pytest.approx(h2)
    window.undo()
    assert _height(window, 0.33) == pytest.approx(eased)


def test_frame_selected_fits_the_selected_keys(window):
    view = _only(window, T_Y)
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, _key_pos(view, T_Y, 2))
    QTest.keyClick(view, QtCore.Qt.Key_F)
    tr = view.transform
    assert tr.t0 < 0.6 < tr.t1 and tr.t1 - tr.t0 < 1.5   # one key: about a second, around it
    x = float(tr.x_of(0.6))
    assert abs(x - (tr.left + tr.width / 2)) < 2
    QTest.keyClick(view, QtCore.Qt.Key_Home)
    assert tr.t0 <= 0.0 and tr.t1 >= 1.0


def test_an_undo_during_a_drag_ends_the_drag_without_an_edit(window):
    d, view = window.document, _only(window, T_Y)
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, _key_pos(view, T_Y, 2))
    QTest.keyClick(view, QtCore.Qt.Key_Delete)          # an edit to undo
    start = _key_pos(view, T_Y, 1)
    QTest.mousePress(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, start)
    _move(view, start + QtCore.QPoint(0, -30))
    assert window.graph_editor.interaction.busy
    window.undo()                                        # Ctrl+Z while the mouse is held
    assert not window.graph_editor.interaction.busy
    _move(view, start + QtCore.QPoint(0, -60))
    QTest.mouseRelease(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier,
                       start + QtCore.QPoint(0, -60))
    # the undo's state stands: four keys, as the clip was made, and Redo redoes the delete
    assert _channel(view, T_Y).curve.times.tolist() == pytest.approx(KEY_TIMES)
    rest_y = d.skeleton.rest_translation[d.skeleton.index[JOINT], 1]
    assert _height(window, 0.3) == pytest.approx(rest_y + 0.2)
    assert d.undo_stack.redo_label.startswith("Delete")


def test_i_on_a_joint_without_keys_keys_its_channels_at_the_cursor(window):
    d, view = window.document, window.graph_editor.view
    d.select("spine_1")
    assert view.visible_channels() == [] and view.message.startswith("spine_1 has no keys")
    d.set_time(0.4)
    view.setFocus()
    QTest.keyClick(view, QtCore.Qt.Key_I)
    shown = view.visible_channels()
    assert {c.id.channel for c in shown} == {"translation", "rotation", "scale"}
    assert all(c.curve.times.tolist() == [0.4] for c in shown)
    j = d.skeleton.index["spine_1"]
    pose = d.sample(0.4)
    assert np.allclose(pose.rotation[j], d.skeleton.rest_rotation[j]) or np.allclose(
        pose.rotation[j], -d.skeleton.rest_rotation[j])
    assert ("spine_1", "rotation") in d.clip.tracks


def test_esc_during_a_key_drag_puts_the_key_back_without_an_undo_step(window):
    d, view = window.document, _only(window, T_Y)
    times = np.linspace(0, 1, 21)
    before = [_height(window, t) for t in times]
    start = _key_pos(view, T_Y, 1)
    QTest.mousePress(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, start)
    _move(view, start + QtCore.QPoint(60, 40))
    assert not np.allclose([_height(window, t) for t in times], before)   # live
    QTest.keyClick(view, QtCore.Qt.Key_Escape)
    QTest.mouseRelease(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier,
                       start + QtCore.QPoint(60, 40))
    assert np.allclose([_height(window, t) for t in times], before, atol=1e-12)
    assert d.undo_stack.undo_label == ""
    assert np.allclose(d.pose.translation, d.sample().translation)


def test_the_handles_box_shows_and_sets_the_selected_keys_handle_type(window):
    view = _only(window, T_Y)
    ge = window.graph_editor
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, _key_pos(view, T_Y, 1))
    assert ge.handle_combo.currentData() == str(_channel(view, T_Y).curve.right_type[1])
    row = ge.handle_combo.findData("vector")
    ge.handle_combo.setCurrentIndex(row)
    ge.handle_combo.activated.emit(row)          # what choosing it in the box does
    cv = _channel(view, T_Y).curve
    assert (cv.left_type[1], cv.right_type[1]) == ("vector", "vector")
    assert cv.right_type[0] != "vector"          # only the selected key
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, _key_pos(view, T_Y, 2))
    shown = ge.handle_combo.currentData()
    assert shown == str(_channel(view, T_Y).curve.right_type[2]) and shown != "vector"


def test_another_clip_drops_the_key_selection_and_frames_its_keys(window):
    d, view = window.document, _only(window, T_Y)
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, _key_pos(view, T_Y, 1))
    assert view.selected
    d.set_current_clip("walk")
    assert view.selected == {}
    walk = d.clip.duration
    assert view.duration == walk and view.transform.t1 >= walk     # the walk framed
    d.set_current_clip("sway")
    assert view.selected == {} and view.duration == 1.0


def test_a_handle_hidden_under_its_key_leaves_the_click_to_the_key(window):
    d, view = window.document, _only(window, T_Y)
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, _key_pos(view, T_Y, 1))
    window.graph_editor.set_interpolation("bezier")
    view.transform.zoom(1 / 40.0, time=True, value=False)   # handles ~2 px from the key
    view.update_view()
    start = _key_pos(view, T_Y, 1)
    _drag(view, start, start + QtCore.QPoint(0, -30))
    assert d.undo_stack.undo_label == "Move keys"


T_X = ChannelId(JOINT, "translation", 0)


def test_keys_of_one_time_on_two_channels_move_together_when_one_is_blocked(window):
    view = _only(window, T_X, T_Y)
    px = view.transform.px_per_s
    # T_X's key at 0.6 moved to about 0.4 (Ctrl: off the frames): a neighbour in the way
    k2 = _key_pos(view, T_X, 2)
    _drag(view, k2, k2 - QtCore.QPoint(int(round(0.2 * px)), 0),
          modifiers=QtCore.Qt.ControlModifier)
    blocker = float(_channel(view, T_X).curve.times[2])
    assert 0.35 < blocker < 0.45
    assert _channel(view, T_Y).curve.times[2] == pytest.approx(0.6)
    # both channels' keys at 0.3 selected, dragged past the blocker
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.NoModifier, _key_pos(view, T_Y, 1))
    QTest.mouseClick(view, QtCore.Qt.LeftButton, QtCore.Qt.ShiftModifier,
                     _key_pos(view, T_X, 1))
    assert {k: v.tolist() for k, v in view.selected.items()} == {T_X: [1], T_Y: [1]}
    start = _key_pos(view, T_Y, 1)
    _drag(view, start, start + QtCore.QPoint(int(round(0.25 * px)), 0))
    tx, ty = (float(_channel(view, c).curve.times[1]) for c in (T_X, T_Y))
    # one offset for both, stopped short of the blocker: still one key time in the timeline
    assert tx == pytest.approx(ty, abs=1e-12)
    assert 0.3 < tx < blocker
