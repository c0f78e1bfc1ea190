"""rigedit.batch.inputs: files, folders and globs into sorted paths; content hashes."""
from pathlib import Path

import pytest

from rigedit.batch.inputs import BatchUsageError, content_hash, expand_inputs, quick_stamp


def _touch(path, text="x"):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def test_files_folders_and_globs_become_one_sorted_list(tmp_path):
    b = _touch(tmp_path / "lib" / "b.bvh")
    a = _touch(tmp_path / "lib" / "sub" / "a.bvh")
    _touch(tmp_path / "lib" / "notes.txt")
    _touch(tmp_path / "lib" / ".hidden.bvh")
    c = _touch(tmp_path / "other" / "c.glb")
    got = expand_inputs("retarget", [tmp_path / "lib", str(tmp_path / "other" / "*.glb"), b])
    assert got == sorted([a, b, c], key=str)   # b once, the .txt and the hidden file left out


def test_a_rig_folder_is_one_input_and_bundled_names_stay_names(tmp_path):
    rig = tmp_path / "rigs" / "fox"
    _touch(rig / "skeleton.json", "{}")
    _touch(rig / "clips" / "walk.json", "{}")
    got = expand_inputs("convert", [tmp_path / "rigs", "humanoid"])
    assert got == sorted([Path("humanoid"), rig], key=str)
    # the mesh jobs search inside folders for meshes, not rigs
    _touch(tmp_path / "meshes" / "cow.OBJ")
    assert [p.name for p in expand_inputs("autorig", [tmp_path / "meshes"])] == ["cow.OBJ"]


def test_recursive_glob(tmp_path):
    deep = _touch(tmp_path / "a" / "b" / "c" / "x.bvh")
    assert expand_inputs("retarget", [f"{tmp_path}/**/*.bvh"]) == [deep]


@pytest.mark.parametrize("what, message", [
    ("missing.bvh", "no such file or folder"),
    ("*.nothing", "the pattern matches no file"),
    ("emptydir", "no retarget input in this folder"),
])
def test_inputs_that_name_nothing_are_bad_input(tmp_path, what, message):
    (tmp_path / "emptydir").mkdir()
    with pytest.raises(BatchUsageError, match=message):
        expand_inputs("retarget", [str(tmp_path / what)])


def test_content_hash_follows_the_bytes_not_the_name(tmp_path):
    one = _touch(tmp_path / "one.bvh", "same")
    two = _touch(tmp_path / "two.bvh", "same")
    assert content_hash(one) == content_hash(two)
    before = quick_stamp(one)
    one.write_text("changed!")
    assert content_hash(one) != content_hash(two)
    assert quick_stamp(one) != before


def test_a_folder_hash_covers_its_files_and_their_names(tmp_path):
    _touch(tmp_path / "r1" / "a.json", "1")
    _touch(tmp_path / "r2" / "b.json", "1")
    assert content_hash(tmp_path / "r1") != content_hash(tmp_path / "r2")
    assert content_hash("humanoid").startswith("sha256:")
