"""Autosave and recovery in the editor (rigedit.ui.autosave): the timer writes only after
changes, a clean close leaves nothing, an editor that dies (an unexpected exception, SIGTERM,
or SIGKILL after an autosave) leaves an entry that the next start offers, and recovering
brings back the edited pose and clip as an unsaved document."""
from testpaths import REPO
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.ui
ROOT = REPO

from cache_fixture import cache  # noqa: E402,F401 - the fixture


@pytest.fixture
def make_editor(cache, qtbot):
    """Windows on the small code-built creature (or a given rig); closed at the end."""
    from rigedit.ui import MainWindow
    from rigedit.ui.fallback import demo_rig

    made = []

    def make(rig=None):
        w = MainWindow(rig or demo_rig())
        qtbot.addWidget(w)
        w.show()
        qtbot.waitExposed(w)
        made.append(w)
        return w

    yield make
    for w in made:
        w.close()


def _entries():
    from rigedit.editor import recovery

    return recovery.list_entries()


def test_autosave_writes_after_an_edit_and_not_when_nothing_changed(make_editor, qtbot):
    w = make_editor()
    auto, doc = w.autosave, w.document
    assert auto.interval == 120.0  # the default: two minutes
    auto.set_interval(0.1)
    qtbot.wait(500)  # several ticks with nothing changed
    assert auto.writes == 0 and _entries() == []
    doc.set_joint_euler(3, [0, 0, 25])
    qtbot.waitUntil(lambda: auto.writes == 1, timeout=5000)
    [entry] = _entries()
    np.testing.assert_array_equal(np.array(entry.info["pose"]), doc.pose_snapshot())
    qtbot.wait(500)
    assert auto.writes == 1  # no change since: no rewrite
    w.timeline.clip_manager.new_clip("stomp")  # a clip edit is a change too
    qtbot.waitUntil(lambda: auto.writes == 2, timeout=5000)
    assert _entries()[0].info["clip"] == "stomp"
    # Saved: nothing left to recover, the entry goes at once.
    doc.mark_saved()
    assert _entries() == []
    assert w.windowTitle().endswith("demo creature")
    doc.undo()
    assert w.windowTitle().endswith("*")
    qtbot.waitUntil(lambda: auto.writes == 3, timeout=5000)


def test_autosave_waits_for_the_end_of_a_drag(make_editor, qtbot):
    w = make_editor()
    w.autosave.set_interval(0)
    w.document.set_joint_euler(3, [0, 0, 25])
    w.document.begin_drag()
    assert not w.autosave.tick() and _entries() == []
    w.document.end_drag("Drag")
    assert w.autosave.tick()  # started in the background
    qtbot.waitUntil(lambda: w.autosave.writes == 1, timeout=10000)
    assert len(_entries()) == 1


def test_background_write_keeps_the_state_it_started_from(make_editor, qtbot, monkeypatch):
    """The timer's write runs in a thread; edits made meanwhile go into the next one, and a
    save meanwhile leaves no entry behind."""
    import threading

    from rigedit.editor import recovery

    w = make_editor()
    auto, doc = w.autosave, w.document
    auto.set_interval(0)
    gate, real = threading.Event(), recovery.write_entry

    def slow(*args, **kwargs):
        gate.wait(10)
        return real(*args, **kwargs)

    monkeypatch.setattr(recovery, "write_entry", slow)
    w.timeline.clip_manager.new_clip("before")  # (a new current clip poses the character from it)
    doc.set_joint_euler(3, [0, 0, 25])
    first = doc.pose_snapshot()
    assert auto.tick() and auto.busy
    assert not auto.tick()  # one write at a time
    doc.set_joint_euler(3, [0, 0, 50])  # while it writes
    w.timeline.clip_manager.rename_clip("after")
    gate.set()
    qtbot.waitUntil(lambda: auto.writes == 1, timeout=10000)
    [entry] = _entries()
    np.testing.assert_array_equal(np.array(entry.info["pose"]), first)
    assert entry.info["clip"] == "before"
    assert auto.tick()
    qtbot.waitUntil(lambda: auto.writes == 2, timeout=10000)
    [entry] = _entries()
    np.testing.assert_array_equal(np.array(entry.info["pose"]), doc.pose_snapshot())
    assert entry.info["clip"] == "after" and "after" in recovery.read_entry(entry)[0].clips
    # Saved while a write runs: the save does not wait for it, and the entry goes once the
    # write is done.
    gate.clear()
    doc.set_joint_euler(3, [0, 0, 60])
    assert auto.tick()
    doc.mark_saved()
    assert auto.busy
    # the thread's signal is queued to the UI thread, where its handler (connected first)
    # removes the entry: wait for the signal itself, not a fixed time
    with qtbot.waitSignal(auto._written_in_thread, timeout=10000):
        gate.set()
    assert not auto.busy
    assert _entries() == [] and auto.writes == 2
    # Closed while a write runs: the close waits for it and leaves nothing.
    gate.clear()
    doc.set_joint_euler(3, [0, 0, 70])
    assert auto.tick()
    threading.Timer(0.3, gate.set).start()
    w.close()
    assert _entries() == []



def test_clean_close_leaves_nothing(make_editor, cache):
    w = make_editor()
    w.document.set_joint_euler(3, [0, 0, 25])
    assert w.autosave.save()
    assert len(_entries()) == 1
    w.close()
    assert _entries() == [] and not w.autosave.folder.exists()


def test_each_window_has_its_own_entry(make_editor):
    a, b = make_editor(), make_editor()
    a.document.set_joint_euler(3, [0, 0, 25])
    b.document.set_joint_euler(4, [0, 0, -25])
    assert a.autosave.save() and b.autosave.save()
    assert a.autosave.folder != b.autosave.folder and len(_entries()) == 2
    a.close()
    assert [e.folder for e in _entries()] == [b.autosave.folder]
    assert b.autosave.crash_save() and b.autosave.writes == 1  # it holds the last edit
    b.document.set_joint_euler(4, [0, 0, -30])
    assert b.autosave.crash_save() and b.autosave.writes == 2


def test_closing_with_unsaved_changes_asks(make_editor, monkeypatch, tmp_path):
    from rigedit.ui import autosave

    answers = []
    monkeypatch.setattr(autosave, "ask_save_changes",
                        lambda parent, name, action: answers.pop(0))
    w = make_editor()
    w.confirm_close = True
    assert w.close()  # nothing unsaved: no question
    w = make_editor()
    w.confirm_close = True
    w.document.set_joint_euler(3, [0, 0, 25])
    assert w.autosave.save()
    answers[:] = ["cancel"]
    assert not w.close() and w.isVisible() and len(_entries()) == 1
    # Save on a rig that has no folder yet asks where (Save As); a cancelled Save As keeps
    # the window open.
    folder = []
    monkeypatch.setattr("PyQt5.QtWidgets.QFileDialog.getExistingDirectory",
                        lambda *a, **k: folder.pop(0))
    answers[:], folder[:] = ["save"], [""]
    assert not w.close() and w.isVisible() and w.document.modified
    answers[:], folder[:] = ["save"], [str(tmp_path / "saved")]
    assert w.close() and (tmp_path / "saved" / "skeleton.json").is_file()
    assert _entries() == []
    w = make_editor()
    w.confirm_close = True
    w.document.set_joint_euler(3, [0, 0, 25])
    answers[:] = ["discard"]
    assert w.close() and _entries() == [] and answers == []


def _stale_entry(rig, pose, clip, t, original):
    """An entry as left by an editor process that no longer runs."""
    from rigedit.editor import recovery

    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return recovery.write_entry(rig, pose, clip, t, original_path=original,
                                folder=recovery.recovery_dir() / f"{proc.pid}-0").parent


def test_recover_restores_pose_and_clip_as_unsaved_and_saves_to_the_original(
        make_editor, tmp_path, monkeypatch):
    from rigedit.io.rig_folder import save_rig_folder
    from rigedit.ui import autosave
    from rigedit.ui.fallback import demo_rig

    original = tmp_path / "creature"
    rig = demo_rig()
    save_rig_folder(original, rig)
    pose = rig.rest_pose()
    pose.set_euler(5, [0, 30, 0], degrees=True)
    folder = _stale_entry(rig, pose.as_array(), None, 0.0, original)
    w = make_editor()
    asked = []
    entry = autosave.offer_recovery(w, ask=lambda win, e: asked.append(e) or "recover")
    assert [e.folder for e in asked] == [folder] and entry.folder == folder
    doc = w.document
    np.testing.assert_array_equal(doc.pose_snapshot(), pose.as_array())
    np.testing.assert_allclose(w.scene.joint_positions, doc.rig.joint_matrices(doc.pose)[:, :3, 3])
    assert doc.modified and w.windowTitle().endswith("*")
    assert "Recovered" in w.statusBar().currentMessage()
    # The old entry is gone only because this editor's own entry now holds the work.
    assert [e.folder for e in _entries()] == [w.autosave.folder]
    # Save goes to the original folder without asking.
    monkeypatch.setattr("PyQt5.QtWidgets.QFileDialog.getExistingDirectory",
                        lambda *a, **k: pytest.fail("Save asked for a folder"))
    assert w.files.save()
    assert not doc.modified
    import rigedit

    saved = rigedit.load_rig(original)
    assert len(saved.skeleton) == len(rig.skeleton)


def test_recovered_bundled_character_saves_as(make_editor, tmp_path, monkeypatch):
    import rigedit
    from rigedit.ui import autosave
    from rigedit.ui.fallback import demo_rig

    rig = demo_rig()
    _stale_entry(rig, rig.rest_pose().as_array(), None, 0.0,
                 rigedit.resolve_rig_path("quadruped"))
    w = make_editor()
    autosave.offer_recovery(w, ask=lambda win, e: "recover")
    assert w.document.rig.path is None
    asked = []
    target = tmp_path / "my copy"
    monkeypatch.setattr("PyQt5.QtWidgets.QFileDialog.getExistingDirectory",
                        lambda *a, **k: asked.append(a) or str(target))
    assert w.files.save()
    assert len(asked) == 1 and (target / "skeleton.json").is_file()


def test_discard_and_later(make_editor):
    from rigedit.ui import autosave
    from rigedit.ui.fallback import demo_rig

    rig = demo_rig()
    a = _stale_entry(rig, rig.rest_pose().as_array(), None, 0.0, None)
    w = make_editor()
    w.document.set_joint_euler(3, [0, 0, 25])  # unsaved work is never replaced
    assert autosave.offer_recovery(w, ask=lambda win, e: "recover") is None
    assert "save or discard the changes" in w.last_error
    w._last_dialog.close()
    w.document.undo()
    assert autosave.offer_recovery(w, ask=lambda win, e: "later") is None
    assert [e.folder for e in _entries()] == [a]  # still there for the next start
    assert autosave.offer_recovery(w, ask=lambda win, e: "discard") is None
    assert _entries() == []
    assert not w.document.modified


def test_entry_of_a_running_editor_is_not_offered(make_editor):
    from rigedit.editor import recovery
    from rigedit.ui import autosave
    from rigedit.ui.fallback import demo_rig

    other = make_editor()  # another editor, still running, with unsaved work
    other.document.set_joint_euler(3, [0, 0, 25])
    assert other.autosave.save()
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        rig = demo_rig()
        recovery.write_entry(rig, rig.rest_pose().as_array(), folder=recovery.entry_folder(
            live.pid))
        w = make_editor()
        assert autosave.offer_recovery(w, ask=lambda win, e: pytest.fail(f"offered {e}")) is None
    finally:
        live.kill()
        live.wait()
    assert len(_entries()) == 2


def test_recovery_dialog_buttons(make_editor, qtbot):
    """The real dialog: Recover is the default button; Later leaves the entry."""
    from PyQt5 import QtCore, QtWidgets

    from rigedit.ui import autosave
    from rigedit.ui.fallback import demo_rig

    rig = demo_rig()
    _stale_entry(rig, rig.rest_pose().as_array(), None, 0.0, None)
    w = make_editor()
    seen = []

    def press_later():
        box = next(b for b in QtWidgets.QApplication.topLevelWidgets()
                   if isinstance(b, QtWidgets.QMessageBox) and b.isVisible())
        seen.append((box.text(), [b.text() for b in box.buttons()],
                     box.defaultButton().text(), box.informativeText()))
        next(b for b in box.buttons() if b.text() == "Later").click()

    QtCore.QTimer.singleShot(300, press_later)
    assert autosave.offer_recovery(w) is None
    [(text, buttons, default, info)] = seen
    assert sorted(buttons) == ["Discard", "Later", "Recover"] and default == "Recover"
    assert "demo creature" in info and "never saved" in info
    assert len(_entries()) == 1


# ---------------------------------------------------------------------- real crashes
_EDITOR = r"""
import json, sys
sys.path.insert(0, {root!r})
from PyQt5 import QtCore, QtWidgets
QtCore.QCoreApplication.setAttribute(QtCore.Qt.AA_ShareOpenGLContexts)
qapp = QtWidgets.QApplication(sys.argv[:1])
import importlib.util
spec = importlib.util.spec_from_file_location("editor_app", {app!r})
editor_app = importlib.util.module_from_spec(spec)
spec.loader.exec_module(editor_app)
from rigedit.ui import MainWindow

def edit():
    w = next(x for x in qapp.topLevelWidgets() if isinstance(x, MainWindow))
    w.document.set_joint_euler(5, [0, 30, 0])
    w.timeline.clip_manager.new_clip("crash test")
    w.timeline.keys.insert_key(all_joints=True)
    print("EDITED", json.dumps(w.document.pose_snapshot().tolist()), flush=True)
    if {mode!r} == "raise":
        QtCore.QTimer.singleShot(0, broken)
        QtCore.QTimer.singleShot(200, lambda: print("ALIVE", flush=True))

def broken():
    raise RuntimeError("simulated bug")

QtCore.QTimer.singleShot(300, edit)
sys.exit(editor_app.main([{rig!r}]))
"""


def _run_editor(tmp_path, mode):
    from rigedit.io.rig_folder import save_rig_folder
    from rigedit.ui.fallback import demo_rig

    rig_dir = tmp_path / "creature"
    if not rig_dir.exists():
        save_rig_folder(rig_dir, demo_rig())
    script = _EDITOR.format(root=str(ROOT), app=str(ROOT / "app.py"), mode=mode,
                            rig=str(rig_dir))
    env = {**os.environ, "QT_QPA_PLATFORM": "xcb", "RIGEDIT_AUTOSAVE_SECONDS": "0"}
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env)
    deadline = time.monotonic() + 120
    pose = None
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        if not line:
            break
        if line.startswith("EDITED "):
            pose = np.array(json.loads(line[len("EDITED "):]))
            if mode != "raise":
                break
        if line.startswith("ALIVE"):
            break
    if pose is None:
        proc.kill()
        pytest.fail(f"the editor did not start: {proc.communicate()[1][-3000:]}")
    return proc, pose, rig_dir


@pytest.mark.parametrize("mode", ["sigterm", "raise"])
def test_crashed_editor_leaves_an_entry_that_a_new_window_recovers(
        make_editor, tmp_path, mode, cache):
    from rigedit.ui import autosave

    proc, pose, rig_dir = _run_editor(tmp_path, mode)
    if mode == "sigterm":
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=60)
        assert proc.returncode == 128 + signal.SIGTERM
        assert "SIGTERM received" in (cache / "rigedit.log").read_text()
    else:
        assert proc.poll() is None  # the exception did not kill it ...
        proc.kill()  # ... a hard crash afterwards (nothing runs: SIGKILL)
        out, err = proc.communicate(timeout=60)
        log = (cache / "rigedit.log").read_text()
        assert "RuntimeError: simulated bug" in log and "Traceback" in log
    assert "Traceback" not in err
    [entry] = _entries()
    assert entry.pid == proc.pid and not entry.alive
    w = make_editor()
    assert autosave.offer_recovery(w, ask=lambda win, e: "recover") is not None
    doc = w.document
    np.testing.assert_array_equal(doc.pose_snapshot(), pose)
    assert doc.current_clip == "crash test"
    clip = doc.clips["crash test"]
    assert len(clip.key_times(doc.skeleton.names[5])) == 1
    assert doc.rig.path == rig_dir and doc.modified
