"""Adversarial manifests and OUTDIRs: entries that parse as JSON but have the wrong shape,
the batch's own names taken by something else, writers' litter among odd output names."""
import json
import os

import pytest

from rigedit.batch import runner
from rigedit.batch.inputs import BatchUsageError
from rigedit.batch.jobs import run_task
from rigedit.batch.manifest import Manifest, rigedit_version
from rigedit.batch.report import write_report
from rigedit.batch.runner import prepare_outdir, remove_temps
from rigedit.batch.tasks import check_options, plan


@pytest.fixture
def done(tmp_path):
    """A noop task run in this process, its entry written: ``(manifest, task, entry)``."""
    src = tmp_path / "in" / "a.bvh"
    src.parent.mkdir()
    src.write_bytes(b"x")
    out = tmp_path / "out"
    out.mkdir()
    task = plan("noop", [src], out, check_options("noop", {}))[0]
    manifest = Manifest(out)
    manifest.write(run_task(task))
    assert manifest.done(task, rigedit_version())
    return manifest, task, manifest.read(task["id"])


@pytest.mark.parametrize("field, value", [
    ("inputs", ["SRC"]),           # a list of the input's name: resume raised TypeError
    ("quality", ["frames"]),       # the report raised AttributeError
    ("input", 7), ("status", None), ("status", 'ok" onclick="alert(1)'), ("outputs", "a.glb"),
    ("unsure", "left arm"),
    ("warnings", [1, 2]), ("target", ["hero"]), ("seconds", "fast"), ("error", {"x": 1}),
])
def test_an_entry_of_the_wrong_shape_is_no_entry(done, field, value):
    manifest, task, entry = done
    bad = {**entry, field: [task["input"]] if value == ["SRC"] else value}
    manifest.path(task["id"]).write_text(json.dumps(bad))
    assert manifest.read(task["id"]) is None
    assert not manifest.done(task, rigedit_version())   # its task runs again
    assert manifest.entries() == []
    write_report(manifest.outdir, "noop", manifest.entries(), tasks=1)   # no crash


def test_a_whole_entry_still_reads(done):
    manifest, task, entry = done
    assert manifest.entries() == [entry]


@pytest.mark.parametrize("name, kind", [("manifest", "file"), ("thumbs", "file"),
                                        ("report.html", "folder"),
                                        ("manifest.json", "folder")])
def test_the_batchs_own_names_taken_are_bad_input_before_any_work(tmp_path, name, kind):
    # a file "manifest" made every entry's write raise FileExistsError after its task ran
    out = tmp_path / "out"
    out.mkdir()
    if kind == "file":
        (out / name).write_text("mine")
    else:
        (out / name).mkdir()
    with pytest.raises(BatchUsageError, match=f"{name}: expected a"):
        prepare_outdir(out)


def test_litter_is_removed_by_name_not_by_pattern(tmp_path):
    srcs = [tmp_path / "in" / n for n in ("*.glb", "walk[1].glb", ".hidden.glb",
                                          ".hidden.glb.glb")]
    tasks = plan("convert", srcs, tmp_path, check_options("convert", {"to": "glb"}))
    outs = [t["outputs"][0] for t in tasks]
    assert outs == ["*.glb", "walk[1].glb", ".hidden.glb", ".hidden.glb.glb"]
    for o in outs:
        (tmp_path / o).write_text("out")
    keep = [tmp_path / ".keep.glb.notes", tmp_path / ".cache"]
    for k in keep:
        k.write_text("mine")
    litter = [tmp_path / ".*.glb.pid1-abc.tmp", tmp_path / ".walk[1].glb.pid2-x.tmp"]
    for li in litter:
        li.write_text("half")
    removed = remove_temps(tmp_path, tasks)
    assert sorted(removed) == sorted(litter)
    assert all(k.exists() for k in keep)              # "*.glb" matched every hidden file
    assert all((tmp_path / o).exists() for o in outs)  # ".hidden.glb.glb" is an output


def test_many_tasks_litter_search_is_one_listing_per_folder(tmp_path, monkeypatch):
    # a glob per output listed OUTDIR once per task: 0.18 s for 250 tasks, 31 s for 4,000
    srcs = [tmp_path / "in" / f"r{i:04d}.glb" for i in range(500)]
    tasks = plan("convert", srcs, tmp_path, check_options("convert", {"to": "glb"}))
    listed = []
    real = os.scandir
    monkeypatch.setattr(runner.os, "scandir", lambda p: listed.append(p) or real(p))
    remove_temps(tmp_path, tasks)
    assert sorted(map(str, listed)) == sorted([str(tmp_path), str(tmp_path / "thumbs")])


def test_an_output_another_batch_wrote_since_under_the_same_name_runs_again(tmp_path):
    # lib1/hero.glb then lib2/hero.glb into one OUTDIR: both write hero.bvh; a resume of
    # lib1 skipped its task although hero.bvh now held lib2's rig
    import rigedit

    out = tmp_path / "out"
    out.mkdir()
    manifest, settings = Manifest(out), check_options("convert", {"to": "bvh",
                                                                 "thumbnails": False})
    tasks = []
    for lib, rig in (("lib1", "humanoid"), ("lib2", "quadruped")):
        src = tmp_path / lib / "hero.glb"
        src.parent.mkdir()
        rigedit.save_rig(rigedit.load_rig(rig), src)
        (task,) = plan("convert", [src], out, settings)
        entry = run_task(task)
        assert entry["status"] == "ok", entry["error"]
        manifest.write(entry)
        tasks.append(task)
    assert tasks[0]["outputs"] == tasks[1]["outputs"] == ["hero.bvh"]
    assert manifest.done(tasks[1], rigedit_version())
    assert not manifest.done(tasks[0], rigedit_version())


def test_a_file_renamed_inside_a_rig_folder_is_a_change(tmp_path):
    # a rename keeps the folder's summed size and latest time: the stamp said "unchanged"
    # and a resume skipped the task although the clip had a new name
    from rigedit.batch.inputs import content_hash, quick_stamp
    from rigedit.batch.manifest import _same_content

    rig = tmp_path / "fox"
    (rig / "clips").mkdir(parents=True)
    (rig / "skeleton.json").write_text("{}")
    (rig / "clips" / "walk.json").write_text("[1]")
    os.utime(rig / "clips" / "walk.json", ns=(1, 10**18))   # older than skeleton.json
    recorded = {"hash": content_hash(rig), "stamp": quick_stamp(rig)}
    assert _same_content(str(rig), recorded)
    os.rename(rig / "clips" / "walk.json", rig / "clips" / "run.json")
    assert not _same_content(str(rig), recorded)
