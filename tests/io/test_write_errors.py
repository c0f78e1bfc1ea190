"""Every write error is one RigWriteError naming the user's path and leaves nothing behind
(issue 19, section 4); a load while another process saves sees one whole state.

Disk full and read-only are real file systems where the test can mount a small tmpfs (it runs
as root in CI) and simulated otherwise (an ``OSError(ENOSPC)`` from ``os.fsync``, which every
atomic write calls before its rename).
"""
import contextlib
import errno
import os
import subprocess
import sys
import textwrap
import uuid
import warnings
from pathlib import Path

import pytest

import rigedit
from builders import cylinder_rig
from rigedit.errors import RigFileError, RigWriteError
from rigedit.io import save_rig_folder
from save_crash_child import rig_state
from testpaths import REPO, TESTS


def _tree(folder):
    """{relative path: bytes} of every file under ``folder`` (hidden ones too)."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(Path(folder).rglob("*"))
            if p.is_file()}


@contextlib.contextmanager
def _mounted(folder, size="200k"):
    folder.mkdir()
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(folder)],
                          capture_output=True)
    if done.returncode:
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr.decode().strip()}")
    try:
        yield folder
    finally:
        subprocess.run(["umount", "-l", str(folder)], check=False)


def _fill(path):
    """Write zeros into ``path`` until the file system is full."""
    with contextlib.suppress(OSError), open(path, "wb") as fh:
        while True:
            fh.write(b"\0" * 4096)
            fh.flush()


@pytest.fixture
def full_disk(tmp_path):
    """A folder on a file system with almost no space left."""
    with _mounted(tmp_path / "disk") as disk:
        _fill(disk / "filler")
        yield disk


@pytest.fixture
def read_only_disk(tmp_path):
    """A folder holding a saved rig folder ``rig``, remounted read-only."""
    with _mounted(tmp_path / "disk", "2m") as disk:
        save_rig_folder(disk / "rig", cylinder_rig())
        subprocess.run(["mount", "-o", "remount,ro", str(disk)], check=True)
        yield disk


def _assert_names(err, path):
    message = str(err.value)
    assert message.startswith(f"{path}: cannot write:") and "\n" not in message, message
    assert ".rigedit-save" not in message and f".{Path(path).name}." not in message, message
    assert isinstance(err.value, RigFileError) and err.value.path == str(path)


# ---------------------------------------------------------------------------- disk full
def test_disk_full_new_rig_folder_is_removed(full_disk):
    before = _tree(full_disk)
    with pytest.raises(RigWriteError, match="No space left on device") as err:
        save_rig_folder(full_disk / "new", cylinder_rig())
    _assert_names(err, full_disk / "new")
    assert err.value.errno == errno.ENOSPC
    assert sorted(p.name for p in full_disk.iterdir()) == ["filler"]
    assert _tree(full_disk) == before


def test_disk_full_existing_rig_folder_keeps_its_state(tmp_path, full_disk):
    rig = full_disk / "rig"
    (full_disk / "filler").unlink()
    save_rig_folder(rig, rig_state("A"))
    old = _tree(rig)
    _fill(full_disk / "filler")
    with pytest.raises(RigWriteError) as err:
        save_rig_folder(rig, rig_state("B"))
    _assert_names(err, rig)
    assert _tree(rig) == old
    assert rigedit.load_rig(rig).name == "state A"


@pytest.mark.parametrize("suffix", [".glb", ".gltf", ".bvh"])
def test_disk_full_single_file_names_it_and_leaves_nothing(full_disk, suffix):
    out = full_disk / f"out{suffix}"
    with pytest.raises(RigWriteError) as err:
        rigedit.save_rig(cylinder_rig(), out)
    _assert_names(err, out)
    assert sorted(p.name for p in full_disk.iterdir()) == ["filler"]


def test_disk_full_simulated(tmp_path, monkeypatch):
    """The same without a mount: the sync before the rename fails with ENOSPC."""
    def full(fd):
        raise OSError(errno.ENOSPC, "No space left on device")
    rig = tmp_path / "rig"
    save_rig_folder(rig, rig_state("A"))
    old = _tree(rig)
    monkeypatch.setattr(os, "fsync", full)
    for target in (rig, tmp_path / "new", tmp_path / "x.glb"):
        with pytest.raises(RigWriteError) as err:
            rigedit.save_rig(rig_state("B"), target)
        _assert_names(err, target)
    assert _tree(rig) == old
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rig"]


def test_cli_disk_full_is_one_line_naming_the_output(full_disk, tmp_path):
    src = tmp_path / "rig"
    save_rig_folder(src, cylinder_rig())
    for out in (full_disk / "x.glb", full_disk / "newrig"):
        done = subprocess.run([sys.executable, "-m", "rigedit", "export", str(src), "-o",
                               str(out)], capture_output=True, text=True, cwd=REPO)
        lines = [line for line in done.stderr.splitlines() if "Warning" not in line]
        assert done.returncode == 2, done.stderr
        assert lines == [f"rigedit: error: {out}: cannot write: No space left on device"], \
            done.stderr
        assert sorted(p.name for p in full_disk.iterdir()) == ["filler"]


# ---------------------------------------------------------------------------- read-only, permission
def test_read_only_rig_folder(read_only_disk):
    rig = read_only_disk / "rig"
    old = _tree(rig)
    with pytest.raises(RigWriteError, match="Read-only file system") as err:
        save_rig_folder(rig, rig_state("B"))
    _assert_names(err, rig)
    assert _tree(rig) == old
    assert len(rigedit.load_rig(rig).vertices) == len(cylinder_rig().vertices)  # loads still


def test_permission_denied_rig_folder_names_it_not_the_staging_folder(tmp_path, monkeypatch):
    rig = tmp_path / "rig"
    save_rig_folder(rig, rig_state("A"))
    old = _tree(rig)
    real_mkdir = Path.mkdir

    def deny(self, *args, **kwargs):
        if ".rigedit-save" in self.parts:
            raise PermissionError(errno.EACCES, "Permission denied", str(self))
        return real_mkdir(self, *args, **kwargs)
    monkeypatch.setattr(Path, "mkdir", deny)
    with pytest.raises(RigWriteError, match="Permission denied") as err:
        save_rig_folder(rig, rig_state("B"))
    _assert_names(err, rig)
    assert isinstance(err.value, OSError) and err.value.errno == errno.EACCES
    assert _tree(rig) == old


def test_unreadable_rig_folder_on_load(tmp_path, monkeypatch):
    """A chmod-000 folder (simulated: root reads it anyway): one RigFileError."""
    rig = tmp_path / "rig"
    save_rig_folder(rig, cylinder_rig())
    real_stat = os.stat

    def deny(path, *args, **kwargs):
        if str(path).startswith(str(rig) + os.sep):
            raise PermissionError(errno.EACCES, "Permission denied", str(path))
        return real_stat(path, *args, **kwargs)
    monkeypatch.setattr(os, "stat", deny)
    with pytest.raises(RigFileError, match="permission denied") as err:
        rigedit.load_rig(rig)
    assert str(err.value).startswith(str(rig)) and not isinstance(err.value, PermissionError)


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads a chmod-000 folder anyway")
def test_chmod_000_rig_folder_on_load(tmp_path):
    rig = tmp_path / "rig"
    save_rig_folder(rig, cylinder_rig())
    rig.chmod(0)
    try:
        with pytest.raises(RigFileError, match="permission denied"):
            rigedit.load_rig(rig)
    finally:
        rig.chmod(0o755)


# ---------------------------------------------------------------------------- concurrency
_SAVER = textwrap.dedent("""
    import os, sys
    sys.path.insert(0, {tests!r})
    from save_crash_child import rig_state
    from rigedit.io import save_rig_folder
    # a mesh of 10,000 vertices: a load takes long enough for saves to land inside it
    states = [rig_state("A", 100, 100), rig_state("B", 100, 100)]
    print("ready", flush=True)
    sys.stdin.readline()
    i = 0
    while i < {n} or not os.path.exists({stop!r}):   # saves for as long as the loads go on
        save_rig_folder({folder!r}, states[i % 2])
        i += 1
    print(i, flush=True)
""")
_LOADER = textwrap.dedent("""
    import sys, warnings
    warnings.simplefilter("ignore")
    import rigedit
    print("ready", flush=True)
    sys.stdin.readline()
    seen, bad = set(), []
    for i in range({n}):
        try:
            rig = rigedit.load_rig({folder!r})
        except Exception as exc:
            bad.append(f"{{type(exc).__name__}}: {{exc}}")
            continue
        state = (rig.name, tuple(sorted(rig.clips)), round(float(rig.vertices[:, 0].max()), 2),
                 round(float(rig.skeleton.rest_translation[1, 1]), 2))
        seen.add(state)
    print(repr((sorted(seen), bad)), flush=True)
""")


def test_loads_while_another_process_saves_see_one_whole_state(tmp_path):
    folder = str(tmp_path / "rig")
    save_rig_folder(folder, rig_state("A", 100, 100))
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    stop = str(tmp_path / "stop")
    procs = [subprocess.Popen([sys.executable, "-c", code.format(tests=str(TESTS), n=50,
                                                                folder=folder, stop=stop)],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                              env=env, cwd=REPO)
             for code in (_SAVER, _LOADER)]
    try:
        for p in procs:
            assert p.stdout.readline().strip() == "ready"
        for p in procs:   # both start at once
            p.stdin.write("go\n")
            p.stdin.flush()
        out = procs[1].communicate(timeout=300)[0]
        Path(stop).touch()
        saves = int(procs[0].communicate(timeout=300)[0].split()[-1])
        assert procs[0].returncode == 0 and saves >= 50
    finally:
        for p in procs:
            if p.poll() is None:
                p.kill()
                p.wait()
    seen, bad = eval(out.strip().splitlines()[-1])
    assert bad == []
    wholes = {("state A", ("bend", "wave"), 0.3, 1.0), ("state B", ("bend", "twist"), 0.35, 1.2)}
    assert set(seen) <= wholes and len(seen) == 2, seen   # both states, each whole
    assert not (Path(folder) / ".rigedit-save").exists()
