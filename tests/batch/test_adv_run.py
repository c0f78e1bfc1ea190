"""Adversarial batches end to end on a local cluster of one worker: OUTDIR inside the
library it reads, a resume after an input changed and the manifest was damaged, the same
file given three ways, a few hundred tasks."""
import json
import os
import time

import rigedit
from rigedit import batch


def test_a_second_run_does_not_take_its_own_outputs_for_inputs(tmp_path):
    lib = tmp_path / "lib"
    lib.mkdir()
    rigedit.save_rig(rigedit.load_rig("humanoid"), lib / "hero.glb")
    out = lib / "out"
    first = batch.run("convert", [lib], out, workers=1, to="glb", thumbnails=False)
    assert (first.tasks, first.failed) == (1, 0)
    assert (out / "hero.glb").is_file()
    # before: lib/out/hero.glb was a second input and both got renamed outputs
    again = batch.run("convert", [lib, f"{lib}/**/*.glb"], out, workers=1, to="glb",
                      thumbnails=False, resume=True)
    assert (again.tasks, again.skipped, again.ran) == (1, 1, 0)
    assert sorted(p.name for p in out.glob("*.glb")) == ["hero.glb"]


def test_resume_after_a_changed_input_and_a_damaged_manifest(tmp_path):
    lib = tmp_path / "lib"
    (lib / "sub").mkdir(parents=True)
    files = [lib / f"t{i:03d}.bvh" for i in range(6)]
    for f in files:
        f.write_bytes(b"a")
    os.symlink(lib, lib / "sub" / "up")   # a loop back to the library
    out = tmp_path / "out"
    # the same file through a loop, as a path and by two patterns: one task each
    inputs = [f"{lib}/**/*.bvh", files[0], f"{lib}/t00*.bvh"]
    first = batch.run("noop", inputs, out, workers=1)
    assert (first.tasks, first.ran, first.failed) == (6, 6, 0)
    ids = [e["task"] for e in first.entries]
    assert len(set(ids)) == 6
    files[1].write_bytes(b"b")                       # same size, new bytes
    st = files[1].stat()
    os.utime(files[1], ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))
    entry = out / "manifest" / f"{ids[2]}.json"
    entry.write_text(entry.read_text()[:40])          # cut short
    (out / "manifest.json").write_text('{"tasks": [')  # the index cut short too
    again = batch.run("noop", inputs, out, workers=1, resume=True)
    assert (again.tasks, again.ran, again.skipped, again.failed) == (6, 2, 4, 0)
    index = json.loads((out / "manifest.json").read_text())
    assert sorted(e["task"] for e in index["tasks"]) == sorted(ids)
    byid = {e["task"]: e for e in index["tasks"]}
    assert byid[ids[1]]["inputs"][str(files[1])]["hash"] != \
        first.entries[1]["inputs"][str(files[1])]["hash"]


def test_a_few_hundred_tasks_write_a_usable_report_and_index(tmp_path):
    lib = tmp_path / "lib"
    lib.mkdir()
    for i in range(300):
        (lib / f"t{i:03d}.bvh").write_bytes(b"x")
    t0 = time.perf_counter()
    s = batch.run("noop", [f"{lib}/*.bvh"], tmp_path / "out", workers=1)
    took = time.perf_counter() - t0
    assert (s.tasks, s.ran, s.failed) == (300, 300, 0)
    page = s.report.read_text()
    assert page.count("<tr class=") == 300 and "300 tasks: 300 ok" in page
    assert len(json.loads(s.manifest.read_text())["tasks"]) == 300
    t1 = time.perf_counter()
    again = batch.run("noop", [f"{lib}/*.bvh"], tmp_path / "out", workers=1, resume=True)
    assert again.skipped == 300 and time.perf_counter() - t1 < max(5.0, took)


def test_a_local_cluster_starts_no_more_workers_than_tasks(tmp_path, monkeypatch):
    # --workers 4 (or one per core by default) for 2 files started 4 processes, each
    # importing rigedit and the renderer
    import distributed

    asked = []
    real = distributed.LocalCluster

    def spy(*args, **kwargs):
        asked.append(kwargs["n_workers"])
        return real(*args, **kwargs)

    monkeypatch.setattr(distributed, "LocalCluster", spy)
    for name in ("a.bvh", "b.bvh"):
        (tmp_path / name).write_bytes(b"x")
    s = batch.run("noop", [f"{tmp_path}/*.bvh"], tmp_path / "out", workers=4)
    assert (s.ran, s.failed) == (2, 0) and asked == [2]
