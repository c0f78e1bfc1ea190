"""Errors are shown and logged, never lost: an exception in a Qt slot, a VTK observer or a
job's completion callback reaches the user (a red status message naming what failed, a
non-modal dialog) and the log file in the cache folder (with the traceback, which the status
bar never shows); the editor keeps running and writes a recovery snapshot.

pytest-qt normally installs its own excepthook for each test (and fails the test on any
exception in a slot); these tests turn that off so the editor's hook is the one that runs.
"""
from testpaths import TESTS
import sys
import warnings

import numpy as np
import pytest

pytestmark = [pytest.mark.ui, pytest.mark.qt_no_exception_capture]

from cache_fixture import cache  # noqa: E402,F401 - the fixture


@pytest.fixture
def editor(cache, qtbot):
    """A window on the small code-built creature, with the cache folder in tmp_path."""
    from rigedit.ui import MainWindow
    from rigedit.ui.fallback import demo_rig

    hook = sys.excepthook
    w = MainWindow(demo_rig())
    qtbot.addWidget(w)
    w.show()
    qtbot.waitExposed(w)
    assert sys.excepthook is not hook  # the editor's hook is installed ...
    yield w
    w.close()
    assert sys.excepthook is hook  # ... and the previous one back after close


def _log(cache):
    return (cache / "rigedit.log").read_text()


def _status(w):
    return w.statusBar().currentMessage()


def test_exception_in_a_qt_slot_is_shown_logged_and_saved(editor, cache, monkeypatch):
    doc = editor.document
    doc.set_joint_euler(3, [20, 0, 0])  # unsaved work

    def broken(*args, **kwargs):
        raise ZeroDivisionError("the pose exploded")

    monkeypatch.setattr(doc, "edit_pose", broken)
    editor.joint_panel.reset_pose_button.click()  # its slot, Document.reset_pose, raises
    shown = editor.error_display.label
    assert shown.isVisible() and "ff6b6b" in shown.styleSheet()  # red, in the status bar
    assert "ZeroDivisionError: the pose exploded" in shown.text()
    assert "reset_pose" in shown.text() and "document.py" in shown.text()  # where it failed
    assert "Traceback" not in shown.text() and "Traceback" not in _status(editor)
    assert str(cache / "rigedit.log") in _status(editor)
    box = editor.error_display.dialog
    assert box.isVisible() and not box.isModal()
    assert "the pose exploded" in box.text() and "recovery" in box.text()
    log = _log(cache)
    assert "Traceback (most recent call last)" in log and "def broken" not in log
    assert "raise ZeroDivisionError" in log and "reset_pose" in log
    # The editor goes on: the work is still there and written for recovery.
    assert editor.isVisible() and doc.modified
    from rigedit.editor import recovery

    [entry] = recovery.list_entries()
    np.testing.assert_array_equal(np.array(entry.info["pose"]), doc.pose_snapshot())
    # A second failure reuses the dialog and counts.
    editor.joint_panel.reset_pose_button.click()
    assert editor.error_display.dialog is box and "2 errors so far" in box.text()
    editor.status("Posed neck")  # later messages do not hide the error ...
    assert shown.isVisible()
    box.accept()  # ... until the user dismissed it
    assert not shown.isVisible()


def test_exception_in_a_vtk_observer_is_shown_not_warned(editor, cache, monkeypatch):
    def broken(j, target):
        raise RuntimeError("IK diverged")

    monkeypatch.setattr(editor.drag, "step", broken)
    editor.plotter.render()
    x, y = (int(round(v)) for v in editor.gizmos.display_position(4))
    iren = editor.plotter.iren.interactor
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        iren.SetEventInformation(x, y)
        iren.InvokeEvent("LeftButtonPressEvent")  # a real press and move, in VTK observers
        assert editor.gizmos.active is not None
        iren.SetEventInformation(x + 12, y + 6)
        iren.InvokeEvent("MouseMoveEvent")
        iren.InvokeEvent("LeftButtonReleaseEvent")
    assert [c for c in caught if issubclass(c.category, RuntimeWarning)] == []
    assert "joint gizmo callback failed: RuntimeError: IK diverged" in \
        editor.error_display.label.text()
    assert "RuntimeError: IK diverged" in _log(cache)
    # gizmos.errors still holds it, so the UI window fixture fails a test when this happens.
    assert len(editor.gizmos.errors) == 1 and "IK diverged" in editor.gizmos.errors[0]
    assert editor.gizmos.active is None  # the end of the drag still ran


def test_exception_in_a_job_completion_callback(editor, cache, qtbot):
    def done(result):
        raise TypeError(f"cannot apply {result}")

    job = editor.run_job("Applying thing", lambda report: 42, done)
    assert job is not None
    qtbot.waitUntil(lambda: editor.job is None, timeout=10000)
    assert "Applying thing failed: TypeError: cannot apply 42" in \
        editor.error_display.label.text()
    assert not editor.progress.isVisible() and not editor.cancel_button.isVisible()
    assert "cannot apply 42" in _log(cache) and "Traceback" in _log(cache)
    # Bad input (a ValueError) stays a plain message, not a bug report.
    job = editor.run_job("Reading", lambda report: 1,
                         lambda r: (_ for _ in ()).throw(ValueError("x.json: expected a list")))
    qtbot.waitUntil(lambda: editor.job is None, timeout=10000)
    assert editor.last_error == "x.json: expected a list"
    editor._last_dialog.close()


def test_unexpected_exception_in_a_worker_is_logged_not_printed(editor, cache, qtbot, capfd):
    def work(report):
        return 1 / 0

    editor.run_job("Crunching", work, lambda r: None)
    qtbot.waitUntil(lambda: editor.job is None, timeout=10000)
    shown = editor.error_display.label.text()
    assert "Crunching failed: ZeroDivisionError: division by zero" in shown
    assert "(in jobs.py:" in shown and "Traceback" not in shown  # innermost rigedit frame
    assert "1 / 0" in _log(cache)
    assert "Traceback" not in capfd.readouterr().err


def test_describe_names_the_innermost_rigedit_frame_on_one_line():
    from rigedit.ui.errors_hook import describe

    def outer():
        from rigedit.editor.document import skeleton_with_moved_joint

        skeleton_with_moved_joint(None, 0, [np.nan, 0, 0])

    try:
        outer()
    except ValueError:
        text = describe(*sys.exc_info())
    assert text.startswith("ValueError: expected a finite joint position, got [nan 0. 0.]")
    assert text.endswith(", skeleton_with_moved_joint)") and "document.py:" in text
    try:
        raise RuntimeError("line one\n  line two" + "x" * 400)
    except RuntimeError:
        text = describe(*sys.exc_info())
    assert "\n" not in text and "line one line two" in text and "..." in text


def test_window_fixture_still_fails_a_test_whose_vtk_callback_raised(tmp_path):
    """The editor shows a failed gizmo callback instead of warning; the UI tests' window
    fixture must still fail the test (it checks ``gizmos.errors``)."""
    import os
    import subprocess
    from pathlib import Path

    tests = TESTS
    (tmp_path / "conftest.py").write_text('pytest_plugins = ["ui_window_fixture"]\n')
    (tmp_path / "test_broken_callback.py").write_text(
        "import numpy as np\n\n\n"
        "def test_drag_with_a_broken_step(window, monkeypatch):\n"
        "    def broken(j, target):\n"
        "        raise RuntimeError('boom in drag_step')\n\n"
        "    monkeypatch.setattr(window.drag, 'step', broken)\n"
        "    window.plotter.render()\n"
        "    x, y = (int(round(v)) for v in window.gizmos.display_position(5))\n"
        "    iren = window.plotter.iren.interactor\n"
        "    iren.SetEventInformation(x, y)\n"
        "    iren.InvokeEvent('LeftButtonPressEvent')\n"
        "    iren.SetEventInformation(x + 12, y + 6)\n"
        "    iren.InvokeEvent('MouseMoveEvent')\n"
        "    iren.InvokeEvent('LeftButtonReleaseEvent')\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(tests), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "--rootdir", str(tmp_path), str(tmp_path)],
                          capture_output=True, text=True, timeout=300, env=env, cwd=tmp_path)
    assert proc.returncode == 1, proc.stdout[-3000:] + proc.stderr[-3000:]
    assert "exceptions in VTK callbacks" in proc.stdout, proc.stdout[-6000:]
    assert "boom in drag_step" in proc.stdout
