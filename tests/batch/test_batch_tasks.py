"""Tasks run in this process (no cluster): plan, run_task's entries, the manifest's resume
rule, and the options checked before any work."""
import os

import pytest

import rigedit
from batch_helpers import run_in_process
from rigedit.batch.inputs import BatchUsageError
from rigedit.batch.manifest import Manifest, rigedit_version
from rigedit.batch.tasks import check_options, plan


@pytest.fixture(scope="module")
def ran(tmp_path_factory):
    """Two motions and a broken file retargeted onto the humanoid, entries written."""
    out, tasks, entries = run_in_process(tmp_path_factory.mktemp("batch"))
    manifest = Manifest(out)
    for e in entries:
        manifest.write(e)
    return out, tasks, entries, manifest


def test_each_good_task_writes_a_rig_with_the_new_clip_and_its_figures(ran):
    out, tasks, entries, _ = ran
    good = [e for e in entries if e["status"] == "ok"]
    assert len(good) == 2
    for e in good:
        (name,) = e["outputs"]
        rig = rigedit.load_rig(out / name)
        assert len(rig.clips) == 1
        q = e["quality"]
        assert q["mapped joints"] > 10
        assert q["unmapped"] == [] and e["unsure"] == []
        assert 0 <= q["bone direction error (deg)"] < 10   # humanoid onto itself
        assert set(e["inputs"]) == {e["input"], "humanoid"}
        assert all(v["hash"].startswith("sha256:") for v in e["inputs"].values())
    assert not list(out.glob(".*"))   # no temporary left


def test_a_broken_input_is_one_failed_entry_with_a_one_line_error(ran):
    _, _, entries, _ = ran
    (bad,) = [e for e in entries if e["status"] != "ok"]
    assert bad["input"].endswith("broken.bvh")
    assert bad["failure"] == "error"
    assert "broken.bvh" in bad["error"] and "\n" not in bad["error"]
    assert "Traceback" not in bad["error"]


def test_resume_skips_what_succeeded_with_the_same_contents(ran):
    out, tasks, entries, manifest = ran
    version = rigedit_version()
    done = [manifest.done(t, version) for t in tasks]
    assert done == [e["status"] == "ok" for e in entries]   # the failed one runs again
    assert not manifest.done(tasks[0], "0.0.0-other")
    other = dict(tasks[0], settings={**tasks[0]["settings"], "clip": "walk"})
    assert not manifest.done(other, version)


def test_resume_hashes_again_when_a_file_looks_changed(ran, tmp_path):
    out, tasks, _, manifest = ran
    version = rigedit_version()
    src = tasks[1]["input"]
    st = os.stat(src)
    os.utime(src, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))   # touched, same bytes
    assert manifest.done(tasks[1], version)
    data = open(src, "rb").read()
    try:
        with open(src, "ab") as fh:
            fh.write(b"\n")   # new bytes: runs again
        assert not manifest.done(tasks[1], version)
    finally:
        with open(src, "wb") as fh:
            fh.write(data)
    assert manifest.done(tasks[1], version)


def test_a_missing_output_runs_again(ran):
    out, tasks, _, manifest = ran
    path = out / tasks[0]["outputs"][0]
    data = path.read_bytes()
    path.unlink()
    try:
        assert not manifest.done(tasks[0], rigedit_version())
    finally:
        path.write_bytes(data)


def test_a_half_written_or_foreign_entry_is_no_entry(ran):
    out, tasks, _, manifest = ran
    path = manifest.path(tasks[0]["id"])
    text = path.read_text()
    try:
        path.write_text(text[: len(text) // 2])
        assert manifest.read(tasks[0]["id"]) is None
        assert not manifest.done(tasks[0], rigedit_version())
    finally:
        path.write_text(text)


def test_outputs_of_inputs_with_one_name_do_not_collide(tmp_path):
    a, b = tmp_path / "a" / "walk.bvh", tmp_path / "b" / "walk.bvh"
    settings = check_options("retarget", {"to": ["humanoid", "quadruped"]})
    tasks = plan("retarget", [a, b], tmp_path, settings)
    names = [t["outputs"][0] for t in tasks]
    assert len(tasks) == 4 and len(set(names)) == 4
    assert len({t["id"] for t in tasks}) == 4


@pytest.mark.parametrize("job, options, message", [
    ("render", {}, "expected the clip"),
    ("render", {"clip": "walk", "size": "13x7"}, "--size"),
    ("render", {"clip": "walk", "fps": float("nan")}, "--fps"),
    ("convert", {"to": "obj"}, "convert --to"),
    ("retarget", {}, "at least one target"),
    ("retarget", {"to": ["no/such/rig.glb"]}, "no such rig"),
    ("autorig", {"method": "magic"}, "--method"),
    ("autorig", {"colour": "red"}, "unknown option colour"),
    ("compress", {}, "expected --max-error"),
    ("compress", {"max_error": -1}, "--max-error"),
    ("dance", {}, "expected a job"),
])
def test_options_that_make_no_sense_are_refused(job, options, message):
    with pytest.raises(BatchUsageError, match=message):
        check_options(job, options)


def test_compress_keeps_its_bound_and_reports_ratio_and_error(tmp_path):
    from batch_helpers import make_motions
    from rigedit.batch.jobs import run_task

    (motion,) = make_motions(tmp_path / "in", 1)
    settings = check_options("compress", {"max_error": 0.05, "thumbnails": False})
    (task,) = plan("compress", [motion], tmp_path, settings)
    entry = run_task(task)
    assert entry["status"] == "ok", entry["error"]
    q = entry["quality"]
    assert 0 < q["max error (cm)"] <= 0.05 and q["ratio"] > 1
    assert q["compressed (KB)"] < q["raw (KB)"]
    assert len(rigedit.load_rig(tmp_path / task["outputs"][0]).clips) == 1


@pytest.mark.slow
def test_render_writes_a_video_and_its_contact_sheet(tmp_path):
    import imageio.v3 as iio

    from rigedit.batch.jobs import run_task

    settings = check_options("render", {"clip": "wave", "size": "64x48", "fps": 4.0,
                                        "video": "gif"})
    (task,) = plan("render", ["humanoid"], tmp_path, settings)
    entry = run_task(task)
    assert entry["status"] == "ok", entry["error"]
    video, sheet = (tmp_path / o for o in entry["outputs"])
    frames = iio.imread(video, index=None)
    assert 6 <= entry["quality"]["frames"] and frames.shape[1:3] == (48, 64)
    assert iio.imread(sheet).shape[:2] == (2 * 48, 3 * 64)
    assert entry["thumbnail"] == entry["outputs"][1]
