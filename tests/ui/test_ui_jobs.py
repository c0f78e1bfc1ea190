"""Work that runs in a worker thread, through the editor's real paths: File > Recompute
weights, its progress bar and Cancel, and the re-bind after an edit-mode drag cancelled.

A slow weights method (monkeypatched into ``rigedit.binding.weights.METHODS``, which every
weights computation goes through) makes the jobs last long enough to watch and cancel."""
import time

import numpy as np
import pytest

pytestmark = [pytest.mark.ui, pytest.mark.filterwarnings("error::RuntimeWarning")]

from rigedit.binding import weights as weights_module  # noqa: E402
from rigedit.binding.weights import compute_weights  # noqa: E402

from ui_window_fixture import limb_joint, menu_action  # noqa: E402

STEPS = 200


@pytest.fixture
def slow_weights(monkeypatch):
    """Make every weights method report progress in STEPS steps of 10 ms before the real
    work; returns a record of the fractions it reported."""
    reported = []

    def slowed(real):
        def slow(vertices, skeleton, progress=None, **options):
            for i in range(STEPS):
                time.sleep(0.01)
                if progress is not None:
                    progress(i / STEPS)     # raises when the user cancelled
                reported.append(i / STEPS)
            return real(vertices, skeleton, progress=progress, **options)
        return slow

    for name, real in list(weights_module.METHODS.items()):
        monkeypatch.setitem(weights_module.METHODS, name, slowed(real))
    return reported


def _progress_values(window):
    values = []
    window.progress.valueChanged.connect(values.append)
    return values


def test_recompute_weights_from_the_menu_gives_compute_weights_result(demo_window, qtbot):
    window = demo_window
    doc = window.document
    rig = doc.rig
    # start from weights that are not the computed ones: everything on the first deforming joint
    first = int(np.flatnonzero(rig.skeleton.deform)[0])
    one = np.zeros_like(rig.binding.weights)
    one[:, 0] = 1.0
    doc.set_weights(np.full_like(rig.binding.indices, first), one, label="Flat weights")
    flat = rig.binding
    expected_idx, expected_w = compute_weights(rig.vertices, rig.skeleton,
                                               weights_module.default_method(rig.faces),
                                               faces=rig.faces)
    assert not np.allclose(flat.weights, expected_w)
    menu_action(window, "File", "Recompute weights").trigger()
    assert window.job is not None
    qtbot.waitUntil(lambda: window.job is None, timeout=30000)
    assert window.last_error is None
    np.testing.assert_array_equal(rig.binding.indices, expected_idx)
    # (the binding renormalises rows: last-bit differences)
    np.testing.assert_allclose(rig.binding.weights, expected_w, rtol=0, atol=1e-14)
    assert doc.undo_stack.undo_label == "Recompute weights" and len(doc.undo_stack) == 2
    # the view skins with the new weights: bend a leg and compare with the model's skinning
    j = limb_joint(rig.skeleton, "front_shin_L")
    doc.set_joint_euler(j, [40, 0, 0])
    np.testing.assert_allclose(window.scene.mesh.points, rig.skin(doc.pose), atol=1e-5)
    doc.undo()
    window.undo_action.trigger()
    assert rig.binding is flat


def test_weights_job_shows_progress_and_cancel_changes_nothing(demo_window, qtbot, slow_weights):
    window = demo_window
    doc = window.document
    binding, skeleton = doc.rig.binding, doc.rig.skeleton
    values = _progress_values(window)
    menu_action(window, "File", "Recompute weights").trigger()
    assert window.progress.isVisible() and window.cancel_button.isVisible()
    qtbot.waitUntil(lambda: any(10 <= v <= 90 for v in values), timeout=10000)
    assert window.job is not None   # still running: the UI thread is free while it works
    window.cancel_button.click()
    qtbot.waitUntil(lambda: window.job is None, timeout=10000)
    assert len(slow_weights) < STEPS        # the worker stopped early
    assert values == sorted(values) and max(values) < 100
    assert not window.progress.isVisible() and not window.cancel_button.isVisible()
    assert doc.rig.binding is binding and doc.rig.skeleton is skeleton
    assert len(doc.undo_stack) == 0
    assert "cancelled" in window.statusBar().currentMessage()
    assert window.last_error is None


def test_rebind_after_an_edit_mode_drag_can_be_cancelled(demo_window, qtbot, slow_weights):
    window = demo_window
    doc = window.document
    rig = doc.rig
    sk0, binding0 = rig.skeleton, rig.binding
    bind0 = sk0.bind_matrices.copy()
    j = limb_joint(sk0, "front_shin_L")
    window.set_mode("edit")
    window.view("side")
    window.plotter.render()
    bones0 = np.array(window.scene.bones.points)
    points0 = window.scene.mesh.points.copy()
    # a real mouse drag of the joint's sphere
    iren = window.plotter.iren.interactor
    x, y = window.gizmos.display_position(j)
    iren.SetEventInformation(int(round(x)), int(round(y)))
    iren.InvokeEvent("LeftButtonPressEvent")
    assert window.gizmos.active == j
    for step in range(1, 6):
        iren.SetEventInformation(int(round(x)) + 6 * step, int(round(y)) + 8 * step)
        iren.InvokeEvent("MouseMoveEvent")
    assert np.abs(np.array(window.scene.bones.points) - bones0).max() > 0.01  # bone follows
    values = _progress_values(window)
    iren.InvokeEvent("LeftButtonReleaseEvent")
    assert window.job is not None and window.cancel_button.isVisible()
    qtbot.waitUntil(lambda: any(v >= 5 for v in values), timeout=10000)
    window.cancel_button.click()
    qtbot.waitUntil(lambda: window.job is None, timeout=10000)
    assert len(slow_weights) < STEPS
    # the rest state is as before: same skeleton and binding, joint, bones, sphere and skin
    assert rig.skeleton is sk0 and rig.binding is binding0
    np.testing.assert_array_equal(rig.skeleton.bind_matrices, bind0)
    np.testing.assert_allclose(np.array(window.scene.bones.points), bones0, atol=1e-9)
    np.testing.assert_allclose(window.gizmos.center(j), bind0[j, :3, 3], atol=1e-6)
    np.testing.assert_array_equal(window.scene.mesh.points, points0)
    assert len(doc.undo_stack) == 0 and window.mode == "edit"
    assert "cancelled" in window.statusBar().currentMessage()


def test_job_runner_alone_bar_stage_cancel_and_one_job_at_a_time(qtbot):
    # JobRunner is a part of its own: a status bar and four callables are all it takes
    from PyQt5 import QtWidgets

    from rigedit.progress import Cancelled
    from rigedit.ui.jobs import JobRunner

    window = QtWidgets.QMainWindow()
    qtbot.addWidget(window)
    said, errors = [], []
    runner = JobRunner(window.statusBar(), said.append, lambda t, m: errors.append((t, m)),
                       lambda what, summary: errors.append((what, summary)),
                       lambda what: errors.append(what))
    changes = []
    runner.changed.connect(lambda: changes.append(runner.job))
    formats, done = [], []

    def work(report):
        for stage in ("read", "read", "solve"):
            report(0.5, stage)
            time.sleep(0.05)
        return 42

    job = runner.run("Working", work, done.append, show_stage=True)
    job.stage.connect(lambda _: formats.append(runner.progress.format()))
    assert runner.job is job and runner.progress.isVisibleTo(window)
    assert runner.run("Other", work, done.append) is None   # one job at a time
    assert errors and errors[0][0] == "Busy"
    qtbot.waitUntil(lambda: done == [42], timeout=10000)
    assert runner.job is None and not runner.progress.isVisibleTo(window)
    assert "Working: solve %p%" in formats
    assert changes[0] is job and changes[-1] is None   # started, then ended

    def endless(report):
        while True:
            report(None)   # raises Cancelled once cancelled
            time.sleep(0.01)

    cancelled = []
    runner.run("Looping", endless, done.append, on_cancel=lambda: cancelled.append(1))
    runner.cancel()
    qtbot.waitUntil(lambda: cancelled == [1], timeout=10000)
    assert said[-1] == "Looping: cancelled" and done == [42]
    from rigedit.ui import jobs

    assert jobs.Cancelled is Cancelled   # one cancellation exception (rigedit.progress)
