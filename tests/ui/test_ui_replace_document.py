"""Opening another rig (or auto-rigging a mesh) over unsaved changes asks first, and edits
made while the new rig was read are asked about again: a user's work is never dropped."""
import pytest

from rigedit.io.rig_folder import save_rig_folder

from cache_fixture import cache  # noqa: F401 - the fixture (XDG cache in tmp)
from test_autosave import make_editor  # noqa: F401 - the fixture

pytestmark = pytest.mark.ui


@pytest.fixture
def asked(monkeypatch):
    from rigedit.ui import autosave

    log = {"answers": [], "actions": []}

    def ask(parent, name, action):
        log["actions"].append(action)
        return log["answers"].pop(0)

    monkeypatch.setattr(autosave, "ask_save_changes", ask)
    return log


def _other_rig_folder(tmp_path):
    from rigedit.ui.fallback import demo_rig

    rig = demo_rig()
    rig.name = "other"
    save_rig_folder(tmp_path / "other", rig)
    return tmp_path / "other"


def test_open_over_unsaved_changes_asks_and_cancel_keeps_them(make_editor, asked, qtbot,
                                                              tmp_path):
    folder = _other_rig_folder(tmp_path)
    w = make_editor()
    w.confirm_close = True
    w.document.set_joint_euler(3, [0, 0, 25])
    rig = w.document.rig
    asked["answers"][:] = ["cancel"]
    assert w.files.open_folder(str(folder)) is None and w.job is None
    assert asked["actions"] == ["opening another rig"]
    assert w.document.rig is rig and w.document.modified
    asked["answers"][:] = ["discard"]
    w.files.open_folder(str(folder))
    qtbot.waitUntil(lambda: w.job is None, timeout=30000)
    assert w.document.rig is not rig and not w.document.modified
    assert asked["answers"] == []


def test_no_question_without_unsaved_changes(make_editor, asked, qtbot, tmp_path):
    folder = _other_rig_folder(tmp_path)
    w = make_editor()
    w.confirm_close = True
    rig = w.document.rig
    w.files.open_folder(str(folder))
    qtbot.waitUntil(lambda: w.job is None, timeout=30000)
    assert w.document.rig is not rig and asked["actions"] == []


def test_edits_made_while_reading_are_asked_about_again(make_editor, asked, tmp_path):
    from rigedit.ui.fallback import demo_rig

    w = make_editor()
    w.confirm_close = True
    check = w.files.replacing("opening another rig")  # nothing unsaved: no question yet
    assert check is not None and asked["actions"] == []
    w.document.set_joint_euler(3, [0, 0, 25])  # the user goes on while the file is read
    rig = w.document.rig
    asked["answers"][:] = ["cancel"]
    w.files._opened(demo_rig(), check)
    assert w.document.rig is rig and w.document.modified  # the edit is kept
    assert "cancelled" in w.statusBar().currentMessage()
    asked["answers"][:] = ["discard"]
    w.files._opened(demo_rig(), check)
    assert w.document.rig is not rig and not w.document.modified
