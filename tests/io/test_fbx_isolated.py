"""FBX files are read in a child process (rigedit.io.fbx_isolated): the parent gets the same
data and the same one-line errors, the reader's warnings, and survives a reader that crashes
or hangs."""
import os
import stat
import warnings

import numpy as np
import pytest

from rigedit.errors import RigFileError
from rigedit.io import fbx_isolated
from rigedit.io.registry import format_of
from testpaths import DATA

MIXAMO = DATA / "fbx" / "mixamo.fbx"


def _fake_python(tmp_path, body):
    """An executable standing in for the child's Python: runs ``body`` (sh)."""
    script = tmp_path / "python"
    script.write_text("#!/bin/sh\n" + body + "\n")
    script.chmod(script.stat().st_mode | stat.S_IEXEC)
    return str(script)


def test_the_registry_reads_fbx_through_the_child():
    assert format_of("x.fbx").read is fbx_isolated.read_fbx


@pytest.mark.skipif(not MIXAMO.exists(), reason=f"shared test data missing: {MIXAMO}")
def test_the_child_gives_the_in_process_result():
    from rigedit.io.fbx_read import read_fbx as read_here

    here = read_here(MIXAMO)
    child = fbx_isolated.read_fbx(MIXAMO)
    assert child.skeleton.names == here.skeleton.names
    np.testing.assert_array_equal(child.skeleton.parents, here.skeleton.parents)
    np.testing.assert_array_equal(child.vertices, here.vertices)
    np.testing.assert_array_equal(child.faces, here.faces)
    np.testing.assert_array_equal(child.weights, here.weights)
    assert sorted(child.clips) == sorted(here.clips)
    assert child.meta.notes == here.meta.notes


def test_a_bad_file_is_the_readers_one_line_error(tmp_path):
    bad = tmp_path / "cut.fbx"
    bad.write_bytes(b"Kaydara FBX Binary  \x00\x1a\x00" + b"\xe8\x1c\x00\x00" + b"\x00" * 40)
    with pytest.raises(RigFileError) as err:
        fbx_isolated.read_fbx(bad)
    assert str(bad) in str(err.value) and "\n" not in str(err.value)


def test_a_reader_that_crashes_is_an_error_naming_the_file(tmp_path, monkeypatch):
    monkeypatch.setattr(fbx_isolated.sys, "executable", _fake_python(tmp_path, "kill -SEGV $$"))
    with pytest.raises(RigFileError, match=r"crashed it \(signal 11\)") as err:
        fbx_isolated.read_fbx(tmp_path / "any.fbx")
    assert err.value.path == str(tmp_path / "any.fbx")


def test_a_reader_that_hangs_is_stopped(tmp_path, monkeypatch):
    monkeypatch.setattr(fbx_isolated.sys, "executable", _fake_python(tmp_path, "sleep 30"))
    monkeypatch.setattr(fbx_isolated, "TIMEOUT", 0.5)
    with pytest.raises(RigFileError, match="did not end"):
        fbx_isolated.read_fbx(tmp_path / "any.fbx")


def test_a_reader_that_says_nothing_is_an_error(tmp_path, monkeypatch):
    monkeypatch.setattr(fbx_isolated.sys, "executable",
                        _fake_python(tmp_path, "echo 'Traceback: boom' >&2; exit 1"))
    with pytest.raises(RigFileError, match=r"exit status 1: Traceback: boom"):
        fbx_isolated.read_fbx(tmp_path / "any.fbx")


def test_the_readers_warnings_reach_the_caller(tmp_path, monkeypatch):
    import pickle

    payload = tmp_path / "payload"
    payload.write_bytes(pickle.dumps(("data", [(UserWarning, "ufbx repaired a thing")])))
    monkeypatch.setattr(fbx_isolated.sys, "executable",
                        _fake_python(tmp_path, f"cat '{payload}'"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert fbx_isolated.read_fbx(tmp_path / "any.fbx") == "data"
    assert [str(w.message) for w in caught] == ["ufbx repaired a thing"]
