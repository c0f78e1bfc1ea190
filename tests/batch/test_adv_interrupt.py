"""An interrupted resume: the tasks it was to redo and did not reach are "not run" in the
report, not rows of their old entries (those are of the input as it was before)."""
import pytest

from rigedit.batch import runner


class _Engine:
    """In place of the Dask engine: runs the tasks here, and stops (as Ctrl-C does) after
    ``limit`` of them."""
    limit = None

    def __init__(self, *args, **kwargs):
        pass

    def start(self, tasks=None):
        return self

    def close(self):
        pass

    def check_outdir(self, outdir):
        return 1

    def map(self, fn, tasks):
        for i, task in enumerate(tasks):
            if self.limit is not None and i >= self.limit:
                raise KeyboardInterrupt
            yield task, fn(task), None


def test_an_interrupted_resume_shows_what_it_did_not_redo_as_not_run(tmp_path, monkeypatch):
    monkeypatch.setattr(runner, "Engine", _Engine)
    lib = tmp_path / "lib"
    lib.mkdir()
    files = [lib / f"t{i}.bvh" for i in range(3)]
    for f in files:
        f.write_bytes(b"a")
    out = tmp_path / "out"
    first = runner.run("noop", [f"{lib}/*.bvh"], out)
    assert first.ran == 3
    for f in files[1:]:
        f.write_bytes(b"bb")   # both to redo
    _Engine.limit = 1
    try:
        with pytest.raises(KeyboardInterrupt):
            runner.run("noop", [f"{lib}/*.bvh"], out, resume=True)
    finally:
        _Engine.limit = None
    page = (out / "report.html").read_text()
    assert "2 tasks: 2 ok, 0 failed, 0 need a look; 1 not run" in page
    assert page.count("<tr class=") == 2 and "t2.bvh" not in page
