"""File > Save through the editor: a bundled character is read-only (Save asks for a new
place), a clip deleted in the timeline is gone from the saved folder, a bad clip name changes
nothing."""
import hashlib
import warnings
from pathlib import Path

import pytest
from PyQt5 import QtWidgets

import rigedit
from rigedit.io.rig_folder import load_rig_folder

pytestmark = pytest.mark.ui


def snapshot(folder):
    """{relative path: (mtime_ns, sha1)} of every file under ``folder``."""
    return {str(p.relative_to(folder)): (p.stat().st_mtime_ns,
                                         hashlib.sha1(p.read_bytes()).hexdigest())
            for p in sorted(Path(folder).rglob("*")) if p.is_file()}


def trigger(window, text):
    action = next(a for a in window.findChildren(QtWidgets.QAction) if a.text() == text)
    action.trigger()


@pytest.fixture
def save_dialog(monkeypatch):
    """Replace the folder dialog: returns the folders set in ``answers`` and records calls."""
    asked = []
    answers = []

    def ask(parent, title, *args, **kwargs):
        asked.append(title)
        return str(answers.pop(0)) if answers else ""

    monkeypatch.setattr(QtWidgets.QFileDialog, "getExistingDirectory", ask)
    return asked, answers


@pytest.fixture
def restore_clips(window):
    rig = window.document.rig
    clips = dict(rig.clips)
    yield
    rig.clips.clear()
    rig.clips.update(clips)
    for name, clip in clips.items():
        clip.name = name


def test_save_on_a_bundled_character_asks_for_a_new_place(window, save_dialog, tmp_path):
    asked, answers = save_dialog
    assets = Path(rigedit.ASSETS_DIR)
    bundled = window.document.rig.path
    assert Path(bundled).resolve().parent == assets.resolve()
    before = snapshot(assets)
    answers.append(tmp_path / "mine")
    (tmp_path / "mine").mkdir()
    trigger(window, "&Save rig")
    assert asked == ["Save rig into folder"]          # Save became Save As
    assert snapshot(assets) == before                 # nothing in the package changed
    assert Path(window.document.rig.path) == tmp_path / "mine"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = load_rig_folder(tmp_path / "mine")
    assert sorted(back.clips) == sorted(window.document.rig.clips)
    assert len(back.vertices) == len(window.document.rig.vertices)


def test_save_as_into_the_bundled_folder_is_refused(window, save_dialog):
    asked, answers = save_dialog
    assets = Path(rigedit.ASSETS_DIR)
    before = snapshot(assets)
    answers.append(assets / "humanoid")
    trigger(window, "Save rig &as...")
    assert asked == ["Save rig into folder"]
    assert snapshot(assets) == before
    assert "bundled" in window.statusBar().currentMessage()
    assert Path(window.document.rig.path).parent.resolve() == assets.resolve()


def test_clip_deleted_in_the_timeline_is_gone_after_save(window, save_dialog, tmp_path,
                                                         restore_clips):
    asked, answers = save_dialog
    folder = tmp_path / "rig"
    folder.mkdir()
    answers.append(folder)
    window.files.save_as()
    (folder / "animations" / "notes.txt").write_text("mine")
    tl = window.timeline
    doc = window.document
    doc.set_current_clip("idle")
    tl.clip_manager.delete_clip()
    doc.set_current_clip("walk")
    assert tl.clip_manager.rename_clip("stroll") == "stroll"
    trigger(window, "&Save rig")
    assert len(asked) == 1                       # saved in place, no second dialog
    names = sorted(p.name for p in (folder / "animations").iterdir())
    assert names == ["head_nod.json", "notes.txt", "run.json", "stroll.json"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert sorted(load_rig_folder(folder).clips) == ["head_nod", "run", "stroll"]


@pytest.mark.parametrize("bad", ["a/b", "..", "line\nbreak", "Walk"])
def test_invalid_clip_name_shows_in_the_status_bar_and_changes_nothing(window, bad,
                                                                      restore_clips):
    doc = window.document
    tl = window.timeline
    doc.set_current_clip("idle")
    names, depth = list(doc.clips), doc.undo_stack.undo_label
    assert tl.clip_manager.rename_clip(bad) is None
    assert list(doc.clips) == names and doc.current_clip == "idle"
    assert doc.undo_stack.undo_label == depth
    message = window.statusBar().currentMessage()
    assert "clip name" in message and repr(bad)[1:-1][:4] in message


def test_save_as_over_another_rig_asks_first(window, save_dialog, tmp_path, monkeypatch):
    from builders import cylinder_rig
    from rigedit.io.rig_folder import save_rig_folder

    asked, answers = save_dialog
    other = tmp_path / "other"
    save_rig_folder(other, cylinder_rig())
    before = snapshot(other)
    questions = []
    monkeypatch.setattr(window.files, "_confirm_replace",
                        lambda path: questions.append(path) or False)
    answers.append(other)
    assert window.files.save_as() is None
    assert questions == [str(other)] and snapshot(other) == before
