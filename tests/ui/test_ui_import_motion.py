"""File > Import motion onto this character, through the real menu action on the bundled
humanoid under Xvfb (only the file dialog is replaced): the Bandai walk becomes one new clip
that moves, as one undo step; a broken BVH changes nothing and names the file."""
from testpaths import REPO
import warnings
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.ui

from PyQt5 import QtWidgets  # noqa: E402

import rigedit  # noqa: E402
from rigedit.rigging.retarget.calibrate import model_stack  # noqa: E402

from ui_window_fixture import answer_file_dialog, menu_action  # noqa: E402

DATA = REPO.parent / "shared" / "data"
WALK = DATA / "bvh-bandai" / "dataset-1_walk_normal_002.bvh"


def _load(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # a BVH's unit guess
        return rigedit.load_rig(path)


def _import(w, qtbot, monkeypatch, path, add=True):
    """Import ``path`` through the menu; with ``add``, press Add clip in the joint map
    dialog (when the retarget gave a clip). Returns the dialog (None when none opened)."""
    asked = answer_file_dialog(monkeypatch, "getOpenFileName", path)
    menu_action(w, "File", "Import motion onto this character").trigger()
    # reading, then retargeting (a second job started when the first one ends)
    # (no event runs between the two: job is None only when both ended)
    qtbot.waitUntil(lambda: w.job is None, timeout=120000)
    assert asked == ["Import motion onto this character"]
    dialog = w.motion_import.dialog
    if add and dialog is not None and dialog.add_button.isEnabled():
        dialog.add_button.click()
    return dialog


def _state(doc):
    return {name: (clip, clip.name) for name, clip in doc.clips.items()}, doc.current_clip


def test_import_bandai_walk_adds_one_moving_clip_as_one_undo_step(humanoid_window, qtbot,
                                                                   monkeypatch):
    if not WALK.exists():
        pytest.skip(f"shared test data not found: {WALK}")
    w = humanoid_window
    doc = w.document
    before, steps = _state(doc), len(doc.undo_stack)

    _import(w, qtbot, monkeypatch, WALK)

    name = WALK.stem
    assert set(doc.clips) == set(before[0]) | {name}, w.statusBar().currentMessage()
    assert doc.current_clip == name
    assert len(doc.undo_stack) == steps + 1
    assert w.info_panel.labels["Clips"].text() == str(len(before[0]) + 1)
    clip = doc.clips[name]
    assert clip.skeleton is doc.skeleton
    source = _load(WALK).clips["take"]
    assert clip.duration == pytest.approx(source.duration, abs=0.05)
    # the character walks: its sampled pose differs over time, and it travels forward
    poses = [clip.sample(t) for t in np.linspace(0, clip.duration, 5)]
    top = 0   # the skeleton's root joint (parent before child) carries the travel
    for a, b in zip(poses, poses[1:]):
        assert np.abs(a.rotation - b.rotation).max() > 1e-2
    travel = np.linalg.norm(poses[-1].translation[top] - poses[0].translation[top])
    assert travel > 0.3, travel   # metres in about one second of walking
    msg = w.statusBar().currentMessage()
    assert f"Imported {WALK.name}" in msg
    mapped = int(msg.split("joint map automatic, ")[1].split(" mapped")[0])
    assert 10 <= mapped <= len(doc.skeleton)
    assert f"{len(doc.skeleton) - mapped} of this character's joints unmapped" in msg
    assert "joint map automatic" in msg
    assert "NOT SURE" not in msg     # the automatic map reaches every body part
    # the editor's import is the headless retarget onto the same character, skin included:
    # its soles are held on the skinned feet, not on the ankle joints (a target snapshot
    # without the binding fell back to the joints and gave another clip)
    headless = rigedit.retarget(_load(WALK), "take", doc.rig, name=name)
    for t in np.linspace(0, clip.duration, 7):
        a, b = clip.sample(t), headless.sample(t)
        assert np.allclose(a.translation, b.translation, atol=1e-6)
        assert np.allclose(a.rotation, b.rotation, atol=1e-6)

    added = clip
    doc.undo()
    assert _state(doc) == before
    assert w.info_panel.labels["Clips"].text() == str(len(before[0]))
    assert len(doc.undo_stack) == steps
    doc.redo()
    assert doc.current_clip == name and doc.clips[name] is added
    assert set(doc.clips) == set(before[0]) | {name}

    # a second import of the same file gets a new name, not a replaced clip
    _import(w, qtbot, monkeypatch, WALK)
    assert doc.current_clip == f"{name} 2"
    assert doc.clips[name] is added


def test_import_broken_bvh_changes_nothing_and_names_the_file(humanoid_window, qtbot,
                                                              monkeypatch, tmp_path):
    w = humanoid_window
    doc = w.document
    bad = tmp_path / "broken_walk.bvh"
    bad.write_text("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n  CHANNELS 6 Xposition\n")
    before, steps = _state(doc), len(doc.undo_stack)

    _import(w, qtbot, monkeypatch, bad)

    assert _state(doc) == before
    assert len(doc.undo_stack) == steps
    assert "broken_walk.bvh" in w.last_error
    assert "broken_walk.bvh" in w.statusBar().currentMessage()


def test_import_motion_without_legs_changes_nothing_and_names_the_file(humanoid_window, qtbot,
                                                                        monkeypatch, tmp_path):
    # a readable BVH whose skeleton is a bare three-joint chain: nothing like legs to map
    motion = tmp_path / "stick.bvh"
    motion.write_text(
        "HIERARCHY\nROOT Base\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition "
        "Zrotation Xrotation Yrotation\n  JOINT Mid\n  {\n    OFFSET 0 10 0\n    CHANNELS 3 "
        "Zrotation Xrotation Yrotation\n    End Site\n    {\n      OFFSET 0 10 0\n    }\n  }\n"
        "}\nMOTION\nFrames: 2\nFrame Time: 0.033333\n0 0 0 0 0 0 0 0 0\n0 0 0 10 0 0 5 0 0\n")
    assert len(_load(motion).skeleton) >= 2   # it reads: the failure is the map
    w = humanoid_window
    doc = w.document
    before, steps = _state(doc), len(doc.undo_stack)

    dialog = _import(w, qtbot, monkeypatch, motion)

    assert _state(doc) == before
    assert len(doc.undo_stack) == steps
    assert "stick.bvh" in w.last_error
    # the map stays open to be mended, with no clip to add
    assert dialog.isVisible() and not dialog.add_button.isEnabled()
    assert dialog.summary.text().startswith("No clip: ")
    dialog.cancel_button.click()
    assert w.motion_import.dialog is None and _state(doc) == before


def test_import_from_rig_folder_asks_which_clip(humanoid_window, qtbot, monkeypatch):
    # a rig folder is chosen by its skeleton.json; with several clips the user picks one
    w = humanoid_window
    doc = w.document
    folder = Path(doc.rig.path)
    offered = []

    def get_item(parent, title, label, items, *args, **kwargs):
        offered.append(list(items))
        return "wave", True

    monkeypatch.setattr(QtWidgets.QInputDialog, "getItem", staticmethod(get_item))
    before = set(doc.clips)

    _import(w, qtbot, monkeypatch, folder / "skeleton.json")

    assert offered == [list(_load(folder).clips)]
    name = f"{folder.name} wave"
    assert set(doc.clips) == before | {name}, w.statusBar().currentMessage()
    assert doc.current_clip == name
    # the wave onto its own character: the waving hand goes where the source clip takes it
    src, new = doc.clips["wave"], doc.clips[name]
    times = np.linspace(0, src.duration, 7)
    hand = doc.skeleton.index["RightHand"]
    a = model_stack(doc.skeleton, src, times)[:, hand, :3, 3]
    b = model_stack(doc.skeleton, new, times)[:, hand, :3, 3]
    assert np.ptp(a, axis=0).max() > 0.1   # the hand moves in the source
    assert np.abs(a - b).max() < 0.05, np.abs(a - b).max()
