"""rigedit.editor.recovery (pure): where recovery entries and the log go, writing and reading them,
which ones are stale; and the document's modified flag that decides when to write."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from rigedit.editor import recovery
from rigedit.editor.document import Document

from cache_fixture import cache  # noqa: E402,F401 - the fixture


def test_cache_folder_follows_xdg(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert recovery.cache_dir() == tmp_path / "rigedit"
    assert recovery.log_path() == tmp_path / "rigedit" / "rigedit.log"
    assert recovery.recovery_dir() == tmp_path / "rigedit" / "recovery"
    monkeypatch.setenv("XDG_CACHE_HOME", "relative/cache")  # ignored, as the XDG spec says
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert recovery.cache_dir() == tmp_path / "home" / ".cache" / "rigedit"
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert recovery.cache_dir() == tmp_path / "home" / ".cache" / "rigedit"


def _edited(rig):
    pose = rig.rest_pose()
    pose.set_euler(1, [10, 20, 30], degrees=True)
    pose.translation[0] += [0.1, 0.2, 0.3]
    return pose.as_array()


def test_entry_round_trip(cache, cyl_rig, tmp_path):
    pose = _edited(cyl_rig)
    snap = recovery.write_entry(cyl_rig, pose, "bend", 0.375, original_path=tmp_path / "orig")
    assert snap.parent == recovery.entry_folder() and snap.parent.parent == cache / "recovery"
    [entry] = recovery.list_entries()
    assert entry.pid == os.getpid() and entry.alive
    assert recovery.stale_entries() == []  # this process runs: not offered
    rig, pose2, clip, t = recovery.read_entry(entry)
    np.testing.assert_array_equal(pose2, pose)
    assert clip == "bend" and t == 0.375 and rig.name == "cylinder"
    assert rig.path == tmp_path / "orig"  # Save goes where the document came from
    np.testing.assert_array_equal(rig.binding.indices, cyl_rig.binding.indices)
    # weights.npz stores float32, as any save does
    np.testing.assert_allclose(rig.binding.weights, cyl_rig.binding.weights, atol=1e-7)
    np.testing.assert_array_equal(rig.skeleton.bind_matrices, cyl_rig.skeleton.bind_matrices)
    assert list(rig.clips) == ["bend"]
    np.testing.assert_array_equal(rig.clips["bend"].key_times("j1"),
                                  cyl_rig.clips["bend"].key_times("j1"))


def test_bundled_or_unsaved_origin_has_no_save_path(cache, cyl_rig):
    import rigedit

    for origin in (None, rigedit.resolve_rig_path("quadruped")):
        recovery.write_entry(cyl_rig, cyl_rig.rest_pose().as_array(), original_path=origin)
        [entry] = recovery.list_entries()
        assert entry.info["bundled"] == (origin is not None)
        assert recovery.read_entry(entry)[0].path is None  # Save asks where (Save As)


def test_newest_complete_snapshot_wins_and_old_ones_go(cache, cyl_rig):
    folder = recovery.entry_folder()
    first = recovery.write_entry(cyl_rig, _edited(cyl_rig), "bend")
    second = recovery.write_entry(cyl_rig, cyl_rig.rest_pose().as_array(), None)
    assert not first.exists() and second.exists()
    assert sorted(p.name for p in folder.iterdir()) == [second.name]
    # A crash in the middle of the next write leaves a snapshot without recovery.json.
    (folder / "99" / "rig").mkdir(parents=True)
    [entry] = recovery.list_entries()
    assert entry.snapshot == second and entry.info["clip"] is None


def test_wrong_pose_is_refused_both_ways(cache, cyl_rig):
    with pytest.raises(ValueError, match="3 joints"):
        recovery.write_entry(cyl_rig, np.zeros((2, 10)))
    snap = recovery.write_entry(cyl_rig, cyl_rig.rest_pose().as_array())
    info = json.loads((snap / "recovery.json").read_text())
    info["pose"] = [[0.0] * 10]
    (snap / "recovery.json").write_text(json.dumps(info))
    [entry] = recovery.list_entries()
    with pytest.raises(ValueError, match="recovery.json"):
        recovery.read_entry(entry)


def _finished_pid():
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_only_entries_of_dead_editors_are_stale(cache, cyl_rig):
    pose = cyl_rig.rest_pose().as_array()
    dead = _finished_pid()
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        start = recovery.process_start(live.pid)
        recovery.write_entry(cyl_rig, pose, folder=recovery.recovery_dir() / f"{dead}-0")
        recovery.write_entry(cyl_rig, pose, folder=recovery.recovery_dir() / f"{live.pid}-{start}")
        recovery.write_entry(cyl_rig, pose)  # this process
        assert len(recovery.list_entries()) == 3
        assert [e.pid for e in recovery.stale_entries()] == [dead]
        if start is not None:  # Linux: a live pid whose start time differs was reused
            reused = recovery.recovery_dir() / f"{live.pid}-{start + 1}"
            recovery.write_entry(cyl_rig, pose, folder=reused)
            assert sorted(e.pid for e in recovery.stale_entries()) == sorted([dead, live.pid])
    finally:
        live.kill()
        live.wait()
    assert live.pid in [e.pid for e in recovery.stale_entries()]  # once it is gone
    for e in recovery.list_entries():
        recovery.remove_entry(e.folder)
    assert recovery.list_entries() == []


def test_document_modified_follows_the_undo_stack(cyl_rig):
    doc = Document(cyl_rig)
    assert not doc.modified
    r0 = doc.undo_stack.revision
    doc.set_joint_euler(1, [0, 0, 10])
    assert doc.modified and doc.undo_stack.revision > r0
    doc.undo()
    assert not doc.modified  # back to the state that was opened
    doc.redo()
    doc.mark_saved()
    assert not doc.modified
    doc.set_joint_euler(1, [0, 0, 20])
    doc.undo()
    assert not doc.modified
    doc.undo()
    assert doc.modified  # before the saved state is a change too
    doc.set_time(0.5)
    doc.set_pose(doc.pose)  # playback and scrubbing are not edits
    r = doc.undo_stack.revision
    doc.select(1)
    assert doc.undo_stack.revision == r
    doc.set_rig(cyl_rig)
    assert not doc.modified
    doc.set_rig(cyl_rig, modified=True)  # a recovered document is unsaved
    assert doc.modified
    doc.mark_saved()
    assert not doc.modified
