"""The joint map of File > Import motion, through the real menu action and dialog on the
bundled humanoid under Xvfb (only the file dialogs are replaced): the map used is shown, saved
as JSON that ``rigedit retarget --map`` reads, edited in the table (an unmapped joint then
keeps its rest pose in the clip), loaded from a file; bad maps name the file and add nothing.
"""
from testpaths import REPO
import json
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

pytestmark = pytest.mark.ui

import rigedit  # noqa: E402
from rigedit.rigging import load_map, retarget_result  # noqa: E402
from rigedit.rigging.retarget.calibrate import model_stack  # noqa: E402
from rigedit.ui.joint_map_dialog import NONE  # noqa: E402

from ui_window_fixture import answer_file_dialog, menu_action  # noqa: E402

DATA = REPO.parent / "shared" / "data"
WALK = DATA / "bvh-bandai" / "dataset-1_walk_normal_002.bvh"


@pytest.fixture(scope="module")
def motion():
    """The Bandai walk (a BVH whose joint names differ from the humanoid's)."""
    if WALK.exists():
        return WALK
    pytest.skip(f"shared test data not found: {WALK}")


def _open_map(w, qtbot, monkeypatch, path):
    """Import ``path`` through the menu up to the joint map dialog (no clip added yet)."""
    answer_file_dialog(monkeypatch, "getOpenFileName", path)
    menu_action(w, "File", "Import motion onto this character").trigger()
    qtbot.waitUntil(lambda: w.job is None, timeout=120000)
    dialog = w.motion_import.dialog
    assert dialog is not None and dialog.isVisible(), w.last_error
    return dialog


def _source(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rigedit.load_rig(path)


def test_map_used_is_shown_and_saved_as_json_the_cli_reads(humanoid_window, qtbot, monkeypatch,
                                                           tmp_path, motion):
    w = humanoid_window
    doc = w.document
    clips_before = set(doc.clips)
    dialog = _open_map(w, qtbot, monkeypatch, motion)
    # nothing is added until Add clip
    assert set(doc.clips) == clips_before
    src = _source(motion)
    expected = retarget_result(src, "take", doc.rig).mapping
    assert dialog.used == expected and dialog.mapping() == expected
    # one row per motion joint, its character joint (or none) beside it
    assert dialog.table.rowCount() == len(src.skeleton)
    for row, name in enumerate(src.skeleton.names):
        assert dialog.table.item(row, 0).text() == name
        assert dialog.combos[row].currentText() == expected.get(name, NONE)
    assert f"{len(expected)} mapped" in dialog.summary.text()
    unmapped = [n for n in doc.skeleton.names if n not in expected.values()]
    assert 0 < len(unmapped) <= 8
    assert dialog.summary.text().endswith(f"kept at their rest pose: {', '.join(unmapped)}.")
    assert dialog.add_button.isEnabled() and not dialog.retarget_button.isEnabled()

    out = tmp_path / "walk_map.json"
    asked = answer_file_dialog(monkeypatch, "getSaveFileName", out)
    dialog.save_button.click()
    assert asked == ["Save joint map"]
    assert json.loads(out.read_text()) == expected
    assert load_map(out, src.skeleton, doc.skeleton) == expected
    assert str(out) in w.statusBar().currentMessage()


def test_edited_map_is_used_and_unmapped_joint_keeps_rest(humanoid_window, qtbot, monkeypatch,
                                                         motion):
    w = humanoid_window
    doc = w.document
    dialog = _open_map(w, qtbot, monkeypatch, motion)
    auto = dict(dialog.used)
    # the motion joint that drives the character's left forearm: unmap it
    src_name = next(s for s, t in auto.items() if t == "LeftForeArm")
    row = dialog.source_names.index(src_name)
    dialog.combos[row].setCurrentText(NONE)
    assert not dialog.add_button.isEnabled()         # the clip on offer is the old map's
    assert dialog.retarget_button.isEnabled()
    assert "edited" in dialog.problem.text()
    dialog.retarget_button.click()
    qtbot.waitUntil(lambda: w.job is None and dialog.add_button.isEnabled(), timeout=60000)
    edited = {s: t for s, t in auto.items() if s != src_name}
    assert dialog.used == edited
    dialog.add_button.click()
    name = motion.stem
    assert doc.current_clip == name, w.last_error
    msg = w.statusBar().currentMessage()
    assert "joint map edited" in msg
    # a body part left out is said, as rigedit retarget warns (the automatic map's is not)
    assert "NOT SURE: the map leaves parts unmapped: left arm" in msg and "LeftForeArm" in msg
    clip = doc.clips[name]
    times = np.linspace(0, clip.duration, 6)
    fore = doc.skeleton.index["LeftForeArm"]
    rest = doc.skeleton.rest_rotation[fore]
    q = np.array([clip.sample(t).rotation[fore] for t in times])
    # unmapped: its local rotation is the rest one in every frame (q and -q are one turn)
    assert np.abs(np.abs(q @ rest) - 1).max() < 1e-9
    # while the automatic map moves it (so the check above could fail)
    target = SimpleNamespace(skeleton=doc.skeleton,
                             clips={k: c for k, c in doc.clips.items() if k != name})
    auto_clip = retarget_result(_source(motion), "take", target, auto).clip
    q_auto = np.array([auto_clip.sample(t).rotation[fore] for t in times])
    assert np.abs(np.abs(q_auto @ rest) - 1).max() > 1e-3


def test_repeated_target_is_refused_in_the_table(humanoid_window, qtbot, monkeypatch, motion):
    dialog = _open_map(humanoid_window, qtbot, monkeypatch, motion)
    rows = [i for i, c in enumerate(dialog.combos) if c.currentText() != NONE]
    target = dialog.combos[rows[0]].currentText()
    dialog.combos[rows[1]].setCurrentText(target)
    assert dialog.repeats() == [target]
    assert target in dialog.problem.text()
    for b in (dialog.retarget_button, dialog.add_button, dialog.save_button):
        assert not b.isEnabled()
    dialog.cancel_button.click()
    assert humanoid_window.motion_import.dialog is None


def test_loaded_map_is_used_and_bad_map_names_the_file(humanoid_window, qtbot, monkeypatch,
                                                       tmp_path, motion):
    w = humanoid_window
    doc = w.document
    dialog = _open_map(w, qtbot, monkeypatch, motion)
    auto = dict(dialog.used)
    # a map file written by hand: only the legs and the spine (the arms stay at rest)
    legs = {s: t for s, t in auto.items() if "Arm" not in t and "Hand" not in t
            and "Shoulder" not in t}
    assert len(legs) < len(auto)
    good = tmp_path / "legs_only.json"
    good.write_text(json.dumps({"map": legs}))
    asked = answer_file_dialog(monkeypatch, "getOpenFileName", good)
    dialog.load_button.click()
    assert asked == ["Load joint map"]
    qtbot.waitUntil(lambda: w.job is None and dialog.add_button.isEnabled(), timeout=60000)
    assert dialog.used == legs and dialog.mapping() == legs

    bad = tmp_path / "typo_map.json"
    bad.write_text(json.dumps({**legs, "Hips": "Hipz"}))
    answer_file_dialog(monkeypatch, "getOpenFileName", bad)
    clips_before = set(doc.clips)
    dialog.load_button.click()
    assert w.job is None
    assert "typo_map.json" in w.last_error and "Hipz" in w.last_error
    assert dialog.used == legs and dialog.mapping() == legs   # what was on show stays
    assert set(doc.clips) == clips_before
    dialog.add_button.click()
    assert "joint map from legs_only.json" in w.statusBar().currentMessage()
    clip = doc.clips[doc.current_clip]
    times = np.linspace(0, clip.duration, 5)
    hand = doc.skeleton.index["RightHand"]
    chest = doc.skeleton.index["Spine2"]
    mats = model_stack(doc.skeleton, clip, times)
    # the arm rides on the chest rigidly: the hand keeps its place in the chest's frame
    rel = np.linalg.inv(mats[:, chest]) @ mats[:, hand]
    assert np.abs(rel - rel[0]).max() < 1e-6
