"""Editor toggles of issue 10: DQS/LBS in the View menu, Recompute weights with a chosen
method, and the joint panel's per-joint "deforms" flag (real window under Xvfb)."""
import numpy as np
import pytest

import pytestqt  # noqa: F401 - needed: without pytest-qt these fail, never skip

pytestmark = pytest.mark.ui

from ui_window_fixture import demo_window, menu_action  # noqa: E402,F401

from rigedit.binding.weights import compute_weights  # noqa: E402


def _twist(window):
    """Twist a joint that has blended vertices 150 degrees about its bone; returns it."""
    d = window.document
    rig = d.rig
    dense = rig.binding.dense()
    # a joint sharing many vertices with its parent: the blend region twists
    shared = [(np.minimum(dense[:, j], dense[:, p]) > 0.2).sum() if p >= 0 else 0
              for j, p in enumerate(rig.skeleton.parents)]
    j = int(np.argmax(shared))
    assert shared[j] > 5
    d.set_joint_euler(j, [150, 0, 0])
    return j


def test_dqs_toggle_skins_the_view_with_dual_quaternions(demo_window, qtbot):
    w = demo_window
    d = w.document
    _twist(w)
    lbs = np.array(w.scene.mesh.points, dtype=float)
    np.testing.assert_allclose(lbs, d.rig.skin(d.pose, method="lbs"), atol=1e-5)
    menu_action(w, "View", "Dual-quaternion skinning").trigger()
    assert w.scene.skinning == "dqs"
    dqs = np.array(w.scene.mesh.points, dtype=float)
    np.testing.assert_allclose(dqs, d.rig.skin(d.pose, method="dqs"), atol=1e-5)
    lo, hi = d.rig.bounds()
    assert np.abs(dqs - lbs).max() > 0.01 * np.linalg.norm(hi - lo)  # the twist shows
    # a newly opened rig keeps the choice
    from rigedit.ui.fallback import demo_rig

    d.set_rig(demo_rig())
    assert w.scene.skinning == "dqs" and w.dqs_action.isChecked()
    w.dqs_action.trigger()
    assert w.scene.skinning == "lbs"


def test_recompute_weights_with_a_chosen_method(demo_window, qtbot):
    w = demo_window
    d = w.document
    rig = d.rig
    assert w.recompute_actions["heat"].isEnabled()
    for method in ("idw", "heat"):
        expected_idx, expected_w = compute_weights(rig.vertices, rig.skeleton, method,
                                                   faces=rig.faces)
        w.recompute_actions[method].trigger()
        qtbot.waitUntil(lambda: w.job is None, timeout=60000)
        assert w.last_error is None
        np.testing.assert_array_equal(rig.binding.indices, expected_idx)
        np.testing.assert_allclose(rig.binding.weights, expected_w, rtol=0, atol=1e-14)
    a, b = (compute_weights(rig.vertices, rig.skeleton, m, faces=rig.faces)[1]
            for m in ("idw", "heat"))
    assert not np.allclose(a, b)  # the two entries do differ


def test_deform_flag_toggle_is_undoable_and_the_joint_takes_no_weight(demo_window, qtbot,
                                                                     tmp_path):
    w = demo_window
    d = w.document
    rig = d.rig
    j = _twist(w)
    d.select(j)
    box = w.joint_panel.deform_box
    assert box.isEnabled() and box.isChecked()
    assert (rig.binding.dense()[:, j] > 0).any()
    depth = len(d.undo_stack)
    box.click()
    assert not box.isChecked() and not rig.skeleton.deform[j]
    assert len(d.undo_stack) == depth + 1
    w.recompute_actions["idw"].trigger()
    qtbot.waitUntil(lambda: w.job is None, timeout=60000)
    assert w.last_error is None
    assert np.all(rig.binding.dense()[:, j] == 0)  # a non-deforming joint takes no weight
    np.testing.assert_allclose(rig.binding.weights.sum(axis=1), 1.0)
    d.undo()  # the recompute
    d.undo()  # the flag
    assert rig.skeleton.deform[j] and box.isChecked()
    d.redo()
    assert not rig.skeleton.deform[j] and not box.isChecked()
    import rigedit  # the flag is saved with the skeleton

    assert w.files.save_to(tmp_path / "rig")
    assert not rigedit.load_rig(tmp_path / "rig").skeleton.deform[j]


def test_video_export_skins_as_the_view_does(demo_window, qtbot, monkeypatch, tmp_path):
    from rigedit.ui import record_dialog

    seen = []
    monkeypatch.setattr(record_dialog, "record_clip",
                        lambda *a, **kw: seen.append(kw["skinning"]) or 1)
    w = demo_window
    w.record_video(tmp_path / "a.mp4", duration=0.1, progress=False)
    w.dqs_action.trigger()
    w.record_video(tmp_path / "b.mp4", duration=0.1, progress=False)
    w.record_video(tmp_path / "c.mp4", duration=0.1, progress=False, skinning="lbs")
    assert seen == ["lbs", "dqs", "lbs"]
