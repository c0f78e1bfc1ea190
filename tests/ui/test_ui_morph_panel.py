"""The Shapes dock: sliders per morph target, keys on the timeline, under Xvfb."""
import numpy as np
import pytest
from PyQt5 import QtCore

from morph_builders import add_targets, quadruped_with_targets
from ui_window_fixture import editor_window, menu_action


@pytest.fixture(scope="module")
def morph_rig():
    return quadruped_with_targets()


@pytest.fixture
def morph_window(qtbot, morph_rig):
    rig = morph_rig
    rig.binding.set_morph_weights(None)
    with editor_window(qtbot, rig) as w:
        yield w


def _mesh_points(w):
    return np.array(w.scene.mesh.points, copy=True)


def test_the_dock_lists_the_shapes_and_view_shapes_toggles_it(morph_window):
    w = morph_window
    panel = w.morph_dock.panel
    assert list(panel.rows) == ["bulge", "squash"]
    assert w.morph_dock.dock.isVisible() and not panel.empty.isVisible()
    act = menu_action(w, "View", "Shapes")
    act.trigger()
    assert not w.morph_dock.dock.isVisible()
    act.trigger()
    assert w.morph_dock.dock.isVisible()


def test_a_slider_drag_moves_the_mesh_and_is_one_undo_step(qtbot, morph_window):
    w = morph_window
    d, row = w.document, w.morph_dock.panel.rows["bulge"]
    before = _mesh_points(w)
    n = len(d.undo_stack)
    row.slider.sliderPressed.emit()
    for v in (100, 400, 800):
        row.slider.setValue(v)          # as a held slider does: valueChanged per step
    assert len(d.undo_stack) == n       # live, no step yet
    row.slider.sliderReleased.emit()
    assert len(d.undo_stack) == n + 1
    assert d.morph.weight("bulge") == pytest.approx(0.8)
    assert row.spin.value() == pytest.approx(0.8)
    moved = _mesh_points(w)
    assert np.abs(moved - before).max() > 0.05    # the scene shows the shape
    w.undo_action.trigger()
    assert d.morph.weight("bulge") == 0.0 and row.slider.value() == 0
    np.testing.assert_allclose(_mesh_points(w), before, atol=1e-6)


def test_the_key_button_keys_the_current_clip_and_the_timeline_shows_it(qtbot, morph_window):
    w = morph_window
    d, row = w.document, w.morph_dock.panel.rows["squash"]
    d.set_time(0.5)
    row.spin.setValue(0.6)              # a typed weight: one step
    assert d.morph.weight("squash") == pytest.approx(0.6)
    assert row.key.text() == "◇"
    qtbot.mouseClick(row.key, QtCore.Qt.LeftButton)
    clip = d.clip
    assert clip.morph_tracks["squash"].sample(0.5) == pytest.approx(0.6)
    assert row.key.text() == "◆"
    assert d.undo_stack.undo_label == "Key squash at 0.50s"
    assert np.any(np.isclose(w.timeline.ruler.summary_keys, 0.5))      # the key row's mark
    assert row.delete_action.isEnabled()
    d.set_time(0.0)
    assert row.key.text() == "◇" and not row.delete_action.isEnabled()
    w.undo_action.trigger()
    assert "squash" not in clip.morph_tracks
    w.redo_action.trigger()
    d.set_time(0.5)
    row.delete_action.trigger()                       # the key button's right-click menu
    assert "squash" not in clip.morph_tracks and row.key.text() == "◇"
    assert d.undo_stack.undo_label == "Delete squash key at 0.50s"


def test_a_rig_without_shapes_hides_the_dock(qtbot):
    from rigedit.ui.fallback import demo_rig

    with editor_window(qtbot, demo_rig()) as w:
        assert not w.morph_dock.dock.isVisible()
        assert w.morph_dock.panel.rows == {}
        w.document.set_rig(add_targets(demo_rig()))     # File > Open of a rig with shapes
        assert w.morph_dock.dock.isVisible()
        assert list(w.morph_dock.panel.rows) == ["bulge", "squash"]
