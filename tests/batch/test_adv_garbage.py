"""Zero-byte files and binary garbage with the right suffix, a rig folder whose skeleton is
cut short: each is one failed entry whose one-line error starts with the file's path, and
the garbage never stops the task of a good file beside it."""
import os

import pytest
import rigedit
from rigedit.batch.jobs import run_task
from rigedit.batch.tasks import check_options, plan

SUFFIXES = {"convert": [".glb", ".gltf", ".bvh", ".fbx"],
            "autorig": [".obj", ".ply", ".stl", ".vtk", ".glb"]}


@pytest.mark.parametrize("job", ["convert", "autorig"])
def test_garbage_is_one_failed_entry_naming_its_file(tmp_path, job):
    rng = __import__("random").Random(7)
    files = []
    for suffix in SUFFIXES[job]:
        files.append(tmp_path / f"zero{suffix}")
        files[-1].write_bytes(b"")
        files.append(tmp_path / f"junk{suffix}")
        files[-1].write_bytes(bytes(rng.randrange(256) for _ in range(3000)))
    options = {"to": "glb"} if job == "convert" else {}
    if job == "convert":
        good = tmp_path / "good.bvh"
        rigedit.save_rig(rigedit.load_rig("humanoid"), good, clips=["walk"])
        files.append(good)
    out = tmp_path / "out"
    out.mkdir()
    tasks = plan(job, files, out, check_options(job, {**options, "thumbnails": False}))
    for task in tasks:
        entry = run_task(task)
        if task["input"].endswith("good.bvh"):
            assert entry["status"] == "ok", entry["error"]
            continue
        assert entry["status"] == "failed" and entry["failure"] == "error"
        error = entry["error"]
        assert error.startswith(task["input"] + ":"), error
        assert "\n" not in error and len(error) <= 300
        assert not any(p.name.startswith(".") for p in out.iterdir())   # no temporaries left
        assert not os.path.exists(out / task["outputs"][0])


def test_a_rig_folder_cut_short_is_one_failed_entry(tmp_path):
    rig = tmp_path / "fox"
    rigedit.save_rig(rigedit.load_rig("quadruped"), rig)
    text = (rig / "skeleton.json").read_text()
    (rig / "skeleton.json").write_text(text[: len(text) // 3])
    (task,) = plan("convert", [rig], tmp_path, check_options("convert", {"to": "glb"}))
    entry = run_task(task)
    assert entry["status"] == "failed" and entry["error"].startswith(str(rig))


def test_a_jobs_figures_are_strict_json_whatever_their_types(tmp_path, monkeypatch):
    # a float32 made json.dump raise in the client (the batch ended); a NaN wrote "NaN",
    # which jq and JSON.parse refuse
    import json

    import numpy as np
    from rigedit.batch import jobs
    from rigedit.batch.manifest import Manifest

    monkeypatch.setitem(jobs._JOBS, "noop", lambda task: (
        {"a": np.float32(1.5), "b": float("nan"), "c": np.arange(3), "d": (np.int64(2),),
         "e": -float("inf"), "f": {"g": np.bool_(True)}}, []))
    src = tmp_path / "a.bvh"
    src.write_bytes(b"x")
    (task,) = plan("noop", [src], tmp_path, check_options("noop", {}))
    entry = run_task(task)
    assert entry["status"] == "ok", entry["error"]
    assert entry["quality"] == {"a": 1.5, "b": None, "c": [0, 1, 2], "d": [2], "e": None,
                                "f": {"g": True}}
    json.dumps(entry, allow_nan=False)
    Manifest(tmp_path).write(entry)
