"""Whole-folder saves (rigedit.io.rig_save): the folder matches the rig, files rigedit did not
write stay, clip names are checked, a killed save leaves the old or the new state, bundled
characters are read-only."""
from testpaths import TESTS
import json
import os
import random
import re
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

import rigedit
from builders import cylinder_rig, write_elk_folder
from rigedit.animation import Clip
from rigedit.animation.clip_names import check_clip_name, check_new_clip_name, clip_file_stem
from rigedit.errors import RigFileError
from rigedit.io.clip_json import clip_to_dict, save_clip
from rigedit.io.rig_folder import load_rig_folder, save_rig_folder
from rigedit.io.rig_save import JOURNAL, STAGING, is_bundled, recover_interrupted_save
from save_crash_child import rig_state

HERE = TESTS


def load(folder):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return load_rig_folder(folder)


def fingerprint(rig):
    """Everything a saved rig folder holds, as comparable plain data."""
    b = rig.binding
    return {"vertices": rig.vertices.round(6).tolist(), "faces": rig.faces.tolist(),
            "rest": rig.skeleton.rest_translation.round(9).tolist(),
            "indices": np.asarray(b.indices).tolist(),
            "weights": np.asarray(b.weights, dtype=np.float32).round(6).tolist(),
            "clips": {name: clip_to_dict(c) for name, c in sorted(rig.clips.items())},
            "name": rig.name}


def listing(folder):
    return sorted(str(p.relative_to(folder)) for p in Path(folder).rglob("*"))


# ---------------------------------------------------------------------- the folder matches
def test_deleted_and_renamed_clips_are_gone_after_a_save(tmp_path):
    folder = tmp_path / "r"
    rig = cylinder_rig()
    rig.clips["wave"] = rig.clips["bend"].copy("wave")
    save_rig_folder(folder, rig)
    (folder / "animations" / "README.txt").write_text("notes")
    (folder / "animations" / "sketch.png").write_bytes(b"\x89PNG not really")
    (folder / "notes.json").write_text('{"not": "a clip"}')
    loaded = load(folder)
    del loaded.clips["wave"]
    clip = loaded.clips.pop("bend")
    clip.name = "stride"
    loaded.clips["stride"] = clip
    save_rig_folder(folder, loaded)
    assert sorted(p.name for p in (folder / "animations").iterdir()) == [
        "README.txt", "sketch.png", "stride.json"]
    assert (folder / "animations" / "README.txt").read_text() == "notes"
    assert (folder / "notes.json").read_text() == '{"not": "a clip"}'
    back = load(folder)
    assert sorted(back.clips) == ["stride"]
    assert json.loads((folder / "rig.json").read_text())["clips"] == {
        "stride": "animations/stride.json"}
    assert not (folder / STAGING).exists()


def test_elk_folder_clip_deleted_in_the_editor_stays_deleted(tmp_path):
    folder = write_elk_folder(tmp_path / "elk")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # weights computed: expected for this layout
        rig = load_rig_folder(folder)
    assert list(rig.clips) == ["bow"]
    rig.clips.clear()
    save_rig_folder(folder, rig)
    assert list(load(folder).clips) == []
    assert (folder / "models" / "body.obj").is_file()   # not rigedit's: kept


def test_clip_keeps_its_file_name_and_a_foreign_clip_file_is_left_alone(tmp_path):
    folder = tmp_path / "r"
    rig = cylinder_rig()
    save_rig_folder(folder, rig)
    # the file was renamed by hand: the clip keeps it across saves
    os.replace(folder / "animations" / "bend.json", folder / "animations" / "my bend.json")
    loaded = load(folder)
    save_rig_folder(folder, loaded)
    assert sorted(os.listdir(folder / "animations")) == ["my bend.json"]
    # a clip file copied in while the rig was open is not rigedit's: kept, loads next time
    extra = loaded.clips["bend"].copy("extra")
    save_clip(folder / "animations" / "extra.json", extra)
    save_rig_folder(folder, loaded)
    assert sorted(load(folder).clips) == ["bend", "extra"]


def test_a_fifo_named_like_a_clip_file_does_not_block_a_save(tmp_path):
    import threading

    folder = tmp_path / "r"
    rig = cylinder_rig()
    save_rig_folder(folder, rig)
    os.mkfifo(folder / "animations" / "pipe.json")
    done = []
    worker = threading.Thread(target=lambda: done.append(save_rig_folder(folder, rig)),
                              daemon=True)   # a blocked open would hang the test run otherwise
    worker.start()
    worker.join(30)
    assert done, "the save blocked on a FIFO in animations/"
    assert (folder / "animations" / "pipe.json").is_fifo()   # not rigedit's: left alone


def test_an_unrecorded_file_of_a_saved_clip_is_its_file_a_second_one_stops_the_save(tmp_path):
    folder = tmp_path / "r"
    rig = cylinder_rig()
    save_rig_folder(folder, rig)
    # a file rigedit has no record of, holding a clip the rig has too (a recovered document,
    # or one saved over a folder it did not come from): it becomes that clip's file
    save_clip(folder / "animations" / "other.json", rig.clips["bend"].copy("wave"))
    rig.clips["wave"] = rig.clips["bend"].copy("wave")
    rig.clips["wave"].loop = False
    files = save_rig_folder(folder, rig)
    assert files == {"bend": "animations/bend.json", "wave": "animations/other.json"}
    assert load(folder).clips["wave"].loop is False
    # a second file holding 'bend', which has its own file: an error naming both, nothing
    # written
    before = listing(folder), (folder / "animations" / "bend.json").read_bytes()
    save_clip(folder / "animations" / "copy.json", rig.clips["bend"])
    rig.clips["bend"].loop = False
    with pytest.raises(RigFileError, match=r"copy\.json: .*'bend'.*bend\.json"):
        save_rig_folder(folder, rig)
    assert (listing(folder), (folder / "animations" / "bend.json").read_bytes()) == (
        sorted(before[0] + ["animations/copy.json"]), before[1])


def test_a_rig_without_a_record_saved_over_an_elk_folder_replaces_its_clip(tmp_path):
    """A document recovered after a crash has no record of the files it came from; saving
    it over its folder writes its clip into the file that holds that clip."""
    folder = write_elk_folder(tmp_path / "elk")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig = load_rig_folder(folder)
        save_rig_folder(tmp_path / "snapshot", rig)
        recovered = load_rig_folder(tmp_path / "snapshot")
    recovered.clips["bow"].loop = False
    save_rig_folder(folder, recovered)
    assert sorted(os.listdir(folder / "animations")) == ["bow.json"]
    assert load(folder).clips["bow"].loop is False


def test_two_files_declaring_one_clip_name_name_both(tmp_path):
    folder = tmp_path / "r"
    rig = cylinder_rig()
    save_rig_folder(folder, rig)
    save_clip(folder / "animations" / "copy.json", rig.clips["bend"])
    with pytest.raises(RigFileError) as info:
        load_rig_folder(folder)
    msg = str(info.value)
    assert "bend.json" in msg and "copy.json" in msg and "'bend'" in msg


# ---------------------------------------------------------------------- clip names
@pytest.mark.parametrize("name", ["", "   ", "a/b", "a\\b", "nul\x00byte", "two\nlines",
                                  "tab\there", ".", "..", " padded", "x" * 129, "sep\u2028"])
def test_invalid_clip_names_are_refused_where_clips_are_made(name, cyl_rig, tmp_path):
    with pytest.raises(ValueError, match="clip name"):
        check_clip_name(name)
    with pytest.raises(ValueError, match="clip name"):
        Clip(name, cyl_rig.skeleton)
    path = tmp_path / "c.json"
    data = clip_to_dict(cyl_rig.clips["bend"])
    data["name"] = name
    path.write_text(json.dumps(data))
    from rigedit.io.clip_json import load_clip
    if name:   # an empty name falls back to the file's stem
        with pytest.raises(RigFileError, match=r"c\.json: .*" + re.escape(repr(name[:20])[:-1])):
            load_clip(path, cyl_rig.skeleton)


@pytest.mark.parametrize("name", ["walk", "Walk 2", "run.fast", "走る", "a-b_c (1)"])
def test_valid_clip_names_pass(name):
    assert check_clip_name(name) == name


def test_names_differing_only_in_case_are_one_name_for_the_editor():
    with pytest.raises(ValueError, match="'Walk'.*ignoring case"):
        check_new_clip_name("Walk", ["walk", "run"])
    assert check_new_clip_name("Walk", ["walk", "run"], old="walk") == "Walk"
    with pytest.raises(ValueError, match="expected a new name"):
        check_new_clip_name("run", ["walk", "run"])


@pytest.mark.parametrize("name,taken,stem", [
    ("walk", set(), "walk"), ("walk", {"walk.json"}, "walk-2"),
    ("Walk", {"walk.json", "walk-2.json"}, "Walk-3"), ("a:b?", set(), "a_b_"),
    ("CON", set(), "_CON"), ("nul.x", set(), "_nul.x"), ("run.", set(), "run"),
    (".hidden", set(), "_.hidden"), ("é" * 128, set(), "é" * 100)])
def test_clip_file_names_are_portable(name, taken, stem):
    assert clip_file_stem(name, taken) == stem


def test_clips_differing_in_case_get_two_files(tmp_path, cyl_rig):
    cyl_rig.clips["Bend"] = cyl_rig.clips["bend"].copy("Bend")
    files = save_rig_folder(tmp_path / "r", cyl_rig)
    assert {f.lower() for f in files.values()} == {"animations/bend.json",
                                                  "animations/bend-2.json"}
    assert sorted(load(tmp_path / "r").clips) == ["Bend", "bend"]


# ---------------------------------------------------------------------- crash safety
def test_interrupted_save_without_journal_is_undone_with_one_is_finished(tmp_path):
    folder = tmp_path / "r"
    a, b = rig_state("A"), rig_state("B")
    save_rig_folder(folder, a)
    (folder / STAGING / "animations").mkdir(parents=True)
    (folder / STAGING / "skeleton.json").write_text("half a fi")
    assert recover_interrupted_save(folder) == "discarded"
    assert fingerprint(load(folder)) == fingerprint(a) and not (folder / STAGING).exists()
    # a save of B that stopped right after its commit point: finished on load
    save_rig_folder(tmp_path / "b", b)
    stage = folder / STAGING
    (stage / "animations").mkdir(parents=True)
    replace = ["mesh.obj", "skeleton.json", "weights.npz", "rig.json", "animations/bend.json",
               "animations/twist.json"]
    for rel in replace:
        (stage / rel).write_bytes((tmp_path / "b" / rel).read_bytes())
    # half applied: two files already moved
    for rel in replace[:2]:
        os.replace(stage / rel, folder / rel)
    (stage / JOURNAL).write_text(json.dumps({"replace": replace,
                                             "delete": ["animations/wave.json"]}))
    assert fingerprint(load(folder)) == fingerprint(b)
    assert not stage.exists() and not (folder / "animations" / "wave.json").exists()


def test_a_damaged_journal_never_deletes_outside_animations(tmp_path):
    folder = tmp_path / "r"
    save_rig_folder(folder, cylinder_rig())
    (tmp_path / "precious.json").write_text("{}")
    (folder / STAGING).mkdir()
    (folder / STAGING / JOURNAL).write_text(json.dumps(
        {"replace": [], "delete": ["../precious.json"]}))
    with pytest.raises(RigFileError, match="COMMIT"):
        load_rig_folder(folder)
    assert (tmp_path / "precious.json").exists()


@pytest.fixture
def saver(tmp_path):
    """The helper process of save_crash_child.py, saving into tmp_path/rig."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    proc = subprocess.Popen([sys.executable, str(HERE / "save_crash_child.py"),
                             str(tmp_path / "rig")], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True, env=env, bufsize=1)
    assert proc.stdout.readline().strip() == "ready"

    def ask(line):
        proc.stdin.write(line + "\n")
        return proc.stdout.readline().strip()

    yield ask, tmp_path / "rig"
    proc.stdin.close()
    proc.wait(timeout=30)


def _states(tmp_path):
    """Fingerprints of the states A and B as loaded back from a clean save."""
    out = {}
    for which in "AB":
        save_rig_folder(tmp_path / f"ref{which}", rig_state(which))
        out[which] = fingerprint(load(tmp_path / f"ref{which}"))
    assert out["A"] != out["B"]
    return out


def _which(folder, states):
    got = fingerprint(load(folder))
    match = [k for k, v in states.items() if v == got]
    assert match, f"the folder loads as neither state A nor state B: clips {sorted(got['clips'])}"
    return match[0]


def test_a_save_killed_before_any_file_operation_leaves_old_or_new(saver, tmp_path):
    """Exhaustive: a save of the other state exits abruptly before its 1st, 2nd, ... file
    operation (open, mkdir, fsync, rename, unlink); each time the folder loads as exactly the
    old state or exactly the new one, and the switch happens at one point."""
    ask, folder = saver
    states = _states(tmp_path)
    save_rig_folder(folder, rig_state("A"))
    (folder / "animations" / "README.txt").write_text("mine")
    outcomes = []
    n, now = 1, "A"
    while True:
        old, new = now, "B" if now == "A" else "A"
        result = ask(f"crash {new} {n}")
        assert result in ("crashed", "completed")
        now = _which(folder, states)   # the load finishes or undoes the crashed save
        if result == "completed":
            assert now == new
            break
        outcomes.append(now == new)
        n += 1
    assert (folder / "animations" / "README.txt").read_text() == "mine"
    assert n > 20, "expected a save to make more than 20 file-system calls"
    # old state up to the commit point, new state after it
    k = outcomes.index(True)
    assert not any(outcomes[:k]) and all(outcomes[k:])
    assert 5 < k < len(outcomes)
    print(f"{n} file-system calls in one save; the new state from call {k + 1} on")


def test_saves_killed_at_random_moments_leave_old_or_new(saver, tmp_path):
    """A process saving A and B alternately is killed with SIGKILL after a random delay,
    40 times; after each kill the folder loads as exactly A or exactly B."""
    ask, folder = saver
    states = _states(tmp_path)
    t0 = time.perf_counter()
    save_rig_folder(folder, rig_state("A"))
    save_rig_folder(folder, rig_state("B"))
    pair = time.perf_counter() - t0   # about one cycle of the saving loop
    rng = random.Random(8)
    seen, mid_save, committed = set(), 0, 0
    for _ in range(40):
        pid = int(ask("loop"))
        time.sleep(rng.uniform(0, pair))
        os.kill(pid, signal.SIGKILL)
        assert ask(f"reap {pid}") == "reaped"
        mid_save += (folder / STAGING).exists()
        committed += (folder / STAGING / JOURNAL).exists()
        seen.add(_which(folder, states))
    assert mid_save >= 10, f"only {mid_save} of 40 kills landed in the middle of a save"
    assert seen == {"A", "B"}
    print(f"40 kills, {mid_save} in the middle of a save ({committed} after its commit "
          f"point); one save pair took {pair:.3f} s")


# ---------------------------------------------------------------------- bundled characters
def test_bundled_characters_are_read_only(tmp_path):
    bundled = rigedit.ASSETS_DIR / "quadruped"
    assert is_bundled(bundled) and is_bundled(bundled / "animations")
    assert is_bundled(Path(rigedit.__file__).parent / "somewhere")
    assert not is_bundled(tmp_path)
    before = listing(rigedit.ASSETS_DIR)
    with pytest.raises(RigFileError, match="bundled"):
        save_rig_folder(bundled, cylinder_rig())
    assert listing(rigedit.ASSETS_DIR) == before


def test_missing_parent_folder_is_an_error_naming_the_folder(tmp_path):
    target = tmp_path / "no" / "such" / "rig"
    with pytest.raises(RigFileError, match=str(target)):
        save_rig_folder(target, cylinder_rig())
    assert not (tmp_path / "no").exists()


def test_a_recovered_rig_given_the_original_record_deletes_a_deleted_clip(tmp_path):
    from rigedit.io.rig_save import loaded_clip_files, remember_clip_files

    folder = write_elk_folder(tmp_path / "elk")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig = load_rig_folder(folder)
        rig.clips.clear()                      # deleted in the editor, then a crash
        save_rig_folder(tmp_path / "snapshot", rig)
        recovered = load_rig_folder(tmp_path / "snapshot")
    assert loaded_clip_files(rig) == {"bow": (folder / "animations" / "bow.json").resolve()}
    save_rig_folder(folder, recovered)         # no record: the unknown file stays
    assert (folder / "animations" / "bow.json").exists()
    remember_clip_files(recovered, loaded_clip_files(rig))
    save_rig_folder(folder, recovered)
    assert list(load(folder).clips) == []


def test_a_load_waits_for_a_save_in_progress_instead_of_undoing_it(tmp_path):
    """Another process's save holds the folder's lock while it stages: a load meanwhile
    must not take the staging folder for a crash's litter and delete it."""
    import threading

    from rigedit.io.rig_save import folder_lock

    folder = tmp_path / "r"
    save_rig_folder(folder, cylinder_rig())
    stage = folder / STAGING
    outcome = []
    with folder_lock(folder):            # a save in progress (the lock is per open file)
        stage.mkdir()
        (stage / "skeleton.json").write_text("being written")
        loader = threading.Thread(target=lambda: outcome.append(
            recover_interrupted_save(folder)))
        loader.start()
        loader.join(0.3)
        assert loader.is_alive() and stage.exists()   # waiting, staging untouched
        stage.joinpath("skeleton.json").unlink()      # the save finishes and cleans up
        stage.rmdir()
    loader.join(10)
    assert outcome == [None]


def test_a_clip_deleted_before_a_crash_stays_deleted_when_the_recovery_is_saved(tmp_path):
    """The recovery entry carries the original folder's clip files (elk layout: rig.json has
    no record of them), so saving the recovered document over it deletes the deleted one."""
    import json as _json

    from rigedit.editor import recovery

    folder = write_elk_folder(tmp_path / "elk")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig = load_rig_folder(folder)
        rig.clips.clear()
        snap = recovery.write_entry(rig, np.zeros((len(rig.skeleton), 10)),
                                    original_path=folder, folder=tmp_path / "entry")
        info = _json.loads((snap / recovery._INFO).read_text())
        recovered, *_ = recovery.read_entry(recovery.RecoveryEntry(snap.parent, snap, info))
    assert recovered.path == folder and recovered.clips == {}
    save_rig_folder(recovered.path, recovered)
    assert not (folder / "animations" / "bow.json").exists()


def test_ctrl_c_after_the_commit_point_waits_for_the_new_state(tmp_path, monkeypatch):
    """SIGINT arriving while the journal is applied is delivered once the folder holds the
    new state, not in the middle (where only the next load would finish the save)."""
    from rigedit.io import rig_save

    folder = tmp_path / "r"
    save_rig_folder(folder, rig_state("A"))
    real_replace = os.replace
    sent = []

    def replace(src, dst):
        if not sent and STAGING in str(src) and STAGING not in str(dst):
            sent.append(dst)
            os.kill(os.getpid(), signal.SIGINT)   # Ctrl-C during the first move into place
        return real_replace(src, dst)

    monkeypatch.setattr(rig_save.os, "replace", replace)
    with pytest.raises(KeyboardInterrupt):
        save_rig_folder(folder, rig_state("B"))
    monkeypatch.undo()
    assert sent and not (folder / STAGING).exists()
    assert fingerprint(load(folder)) == fingerprint(load(_ref(tmp_path, "B")))


def _ref(tmp_path, which):
    save_rig_folder(tmp_path / f"ref{which}", rig_state(which))
    return tmp_path / f"ref{which}"
