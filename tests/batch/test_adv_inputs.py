"""Adversarial inputs of a batch: symlinks (to a file, to a folder, loops), an OUTDIR inside
the searched folder, the same file named twice, names with unusual characters."""
import os
import time

import pytest

from rigedit.batch.inputs import BatchUsageError, expand_inputs


def _touch(path, text="x"):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def _unlisted(monkeypatch, name):
    """Folders called ``name`` cannot be listed (as for a user without the right)."""
    real = os.scandir

    def scandir(path="."):
        if str(path).endswith(name):
            raise PermissionError(13, "Permission denied", str(path))
        return real(path)

    monkeypatch.setattr(os, "scandir", scandir)


def test_a_recursive_glob_ends_on_symlink_loops(tmp_path):
    # two links to "." made glob's own ** list 2**40 paths (it never came back)
    sub = tmp_path / "lib" / "sub"
    x = _touch(sub / "x.bvh")
    os.symlink(".", sub / "a")
    os.symlink(".", sub / "b")
    t0 = time.perf_counter()
    assert expand_inputs("retarget", [f"{tmp_path}/lib/**/*.bvh"]) == [x]
    assert expand_inputs("retarget", [tmp_path / "lib"]) == [x]
    assert time.perf_counter() - t0 < 5


def test_a_symlink_loop_file_is_a_task_not_a_crash(tmp_path):
    # Path.resolve raised RuntimeError("Symlink loop") out of the command
    a = _touch(tmp_path / "lib" / "a.bvh")
    os.symlink("loop.bvh", tmp_path / "lib" / "loop.bvh")
    got = expand_inputs("retarget", [tmp_path / "lib"])
    assert got == [a, tmp_path / "lib" / "loop.bvh"]
    with pytest.raises(BatchUsageError, match="no such file"):   # named alone: nothing there
        expand_inputs("retarget", [tmp_path / "lib" / "loop.bvh"])


def test_a_symlinked_sub_folder_is_searched_and_a_link_to_a_file_is_its_target(tmp_path):
    real = _touch(tmp_path / "elsewhere" / "run.bvh")
    (tmp_path / "lib").mkdir()
    os.symlink(tmp_path / "elsewhere", tmp_path / "lib" / "linked")
    os.symlink(real, tmp_path / "lib" / "alias.bvh")
    # the folder, the link to the file, the file itself and a glob: one input
    got = expand_inputs("retarget", [tmp_path / "lib", tmp_path / "lib" / "alias.bvh", real,
                                     f"{tmp_path}/elsewhere/*.bvh"])
    assert got == [real]


def test_outdir_inside_the_searched_folder_is_left_out(tmp_path):
    lib = tmp_path / "lib"
    walk = _touch(lib / "walk.bvh")
    out = lib / "out"
    _touch(out / "walk__humanoid.glb")   # a first run's output
    _touch(out / "sub" / "more.bvh")
    assert expand_inputs("retarget", [lib], outdir=out) == [walk]
    assert expand_inputs("retarget", [f"{lib}/**/*.bvh"], outdir=out) == [walk]
    with pytest.raises(BatchUsageError, match="matches no file outside OUTDIR"):
        expand_inputs("retarget", [f"{lib}/**/*.glb"], outdir=out)
    with pytest.raises(BatchUsageError, match="matches no file outside OUTDIR"):
        expand_inputs("retarget", [f"{out}/*.glb"], outdir=out)
    with pytest.raises(BatchUsageError, match="OUTDIR itself"):
        expand_inputs("retarget", [lib], outdir=lib)
    # a file named on its own is taken even there
    assert expand_inputs("retarget", [out / "walk__humanoid.glb"], outdir=out) == \
        [out / "walk__humanoid.glb"]


@pytest.mark.parametrize("name", ["my walk.bvh", "marche_é_歩く.bvh", "-walk.bvh", "#1 walk.bvh",
                                  "100% walk.bvh", "it's \"walk\".bvh",
                                  "<script>alert(1)<\\script>.bvh", "walk[1].bvh"])
def test_unusual_names_are_found_once_by_folder_glob_and_path(tmp_path, name):
    f = _touch(tmp_path / "lib" / name)
    got = expand_inputs("retarget", [tmp_path / "lib", f, f"{tmp_path}/lib/*.bvh"])
    assert got == [f]


def test_a_folder_named_like_a_file_and_empty_files(tmp_path):
    (tmp_path / "lib" / "x.bvh").mkdir(parents=True)
    empty = _touch(tmp_path / "lib" / "empty.bvh", "")
    assert expand_inputs("retarget", [tmp_path / "lib", f"{tmp_path}/lib/*.bvh"]) == [empty]
    with pytest.raises(BatchUsageError, match="no retarget input in this folder"):
        expand_inputs("retarget", [tmp_path / "lib" / "x.bvh"])


def test_a_sub_folder_that_cannot_be_read_is_said_not_skipped(tmp_path, monkeypatch):
    # os.walk passed over it in silence: the batch ran without its files
    _touch(tmp_path / "lib" / "a.bvh")
    _touch(tmp_path / "lib" / "locked" / "b.bvh")
    _unlisted(monkeypatch, "locked")
    for given in (tmp_path / "lib", f"{tmp_path}/lib/**/*.bvh"):
        with pytest.raises(BatchUsageError, match="locked: cannot read this folder "
                                                  r"\(Permission denied\)"):
            expand_inputs("retarget", [given])


@pytest.mark.parametrize("empty", ["", " "])
def test_an_empty_input_name_is_refused_not_the_working_folder(tmp_path, monkeypatch, empty):
    # `rigedit batch convert "$DIR"` with DIR unset searched the working folder
    _touch(tmp_path / "cwd" / "stray.bvh")
    monkeypatch.chdir(tmp_path / "cwd")
    with pytest.raises(BatchUsageError, match="empty name"):
        expand_inputs("retarget", [empty])


def test_a_batch_goes_on_past_an_unreadable_folder_and_says_so(tmp_path, monkeypatch):
    # lost+found at the top of a volume is unreadable to a user: said, not fatal
    from rigedit.batch.runner import run

    a = _touch(tmp_path / "lib" / "a.bvh")
    _touch(tmp_path / "lib" / "lost+found" / "b.bvh")
    _unlisted(monkeypatch, "lost+found")
    skipped = []
    assert expand_inputs("retarget", [tmp_path / "lib"], skipped=skipped) == [a]
    assert skipped == [(str(tmp_path / "lib" / "lost+found"), "Permission denied")]
    monkeypatch.setattr("rigedit.batch.runner.Engine.start", lambda self, tasks=None: 1 / 0)
    with pytest.warns(UserWarning, match=r"lost\+found: cannot read this folder"):
        with pytest.raises(ZeroDivisionError):   # stopped where the cluster would start
            run("retarget", [tmp_path / "lib"], tmp_path / "out", to=["humanoid"])
