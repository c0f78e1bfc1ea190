"""A file name that is not UTF-8 (``caf\\xe9.glb``, as old archives unpack): Python holds it
as ``caf\\udce9``, which ``str.encode`` refuses. Planning the batch raised
UnicodeEncodeError (an internal error for the whole batch); now it is one task like any."""
import os
from pathlib import Path
from urllib.parse import unquote_to_bytes, urlsplit

import pytest
import rigedit
from rigedit.batch.inputs import expand_inputs
from rigedit.batch.jobs import run_task
from rigedit.batch.manifest import Manifest, rigedit_version
from rigedit.batch.report import write_report
from rigedit.batch.tasks import check_options, plan


@pytest.fixture
def latin1(tmp_path):
    lib = tmp_path / "lib"
    lib.mkdir()
    good = lib / "hero.glb"
    rigedit.save_rig(rigedit.load_rig("humanoid"), good)
    odd = os.fsencode(lib) + b"/caf\xe9.glb"
    with open(odd, "wb") as fh:
        fh.write(good.read_bytes())
    return lib, Path(os.fsdecode(odd))


def test_a_name_that_is_not_utf8_is_a_task_with_a_report_row(latin1, tmp_path):
    lib, odd = latin1
    sources = expand_inputs("convert", [lib])
    assert odd in sources
    out = tmp_path / "out"
    out.mkdir()
    tasks = plan("convert", sources, out, check_options("convert", {"to": "bvh",
                                                                    "thumbnails": False}))
    task = next(t for t in tasks if t["input"] == str(odd))
    assert task["outputs"] == [os.fsdecode(b"caf\xe9.bvh")]
    manifest = Manifest(out)
    entry = run_task(task)
    assert entry["status"] == "ok", entry["error"]
    manifest.write(entry)
    assert manifest.read(task["id"]) == entry and manifest.done(task, rigedit_version())
    assert (out / task["outputs"][0]).is_file()
    page = write_report(out, "convert", [entry])
    text = page.read_text(encoding="utf-8")   # valid UTF-8, the odd byte shown as U+FFFD
    assert "caf\ufffd.glb" in text
    href = next(h for h in (p.split('"')[0] for p in text.split('href="')[1:]))
    assert os.path.isfile(os.fsencode(out) + b"/" + unquote_to_bytes(urlsplit(href).path))


def test_a_retarget_never_changes_the_target_its_worker_shares(tmp_path, monkeypatch):
    # the cached target lent itself (its clips changed, then restored): two tasks at once on
    # a threaded worker wrote each other's clip when both clips had one name
    from batch_helpers import make_motions
    from rigedit.batch import jobs
    from rigedit.io import save

    (motion,) = make_motions(tmp_path / "in", 1)
    (task,) = plan("retarget", [motion], tmp_path, check_options(
        "retarget", {"to": ["humanoid"], "thumbnails": False}))
    from rigedit.batch.inputs import content_hash

    # the very object the task gets: cached under the hash the task records
    shared = jobs._rig_option("humanoid", {"hashes": {"humanoid": content_hash("humanoid")}})
    before = dict(shared.clips)
    seen = []
    real = save.save_rig

    def spy(rig, path, **kw):
        seen.append((rig is shared, dict(shared.clips) == before, sorted(rig.clips)))
        return real(rig, path, **kw)

    monkeypatch.setattr(save, "save_rig", spy)
    entry = run_task(task)
    assert entry["status"] == "ok", entry["error"]
    (is_shared, untouched, clips), = seen
    assert not is_shared and untouched
    assert shared.clips == before


def test_a_target_edited_with_its_size_and_time_kept_is_read_again(tmp_path):
    # a worker's cache was keyed by size and mtime: an edit that kept both (cp -p, a tar)
    # retargeted onto the old target while the entry recorded the new one's hash
    from batch_helpers import make_motions
    from rigedit.batch.inputs import quick_stamp

    target = tmp_path / "hero"
    rigedit.save_rig(rigedit.load_rig("humanoid"), target)   # a rig folder
    (motion,) = make_motions(tmp_path / "in", 1)
    settings = check_options("retarget", {"to": [str(target)], "thumbnails": False})
    (task,) = plan("retarget", [motion], tmp_path / "out", settings)
    (tmp_path / "out").mkdir()
    skeleton = target / "skeleton.json"
    heights = []
    for edit in (False, True):
        if edit:   # the hips 10 cm lower, the file's size and time as they were
            st = skeleton.stat()
            skeleton.write_text(skeleton.read_text().replace("0.982647735", "0.882647735", 1))
            os.utime(skeleton, ns=(st.st_atime_ns, st.st_mtime_ns))
            assert quick_stamp(target) == stamp   # what the cache was keyed by
        stamp = quick_stamp(target)
        entry = run_task(task)
        assert entry["status"] == "ok", entry["error"]
        out = rigedit.load_rig(tmp_path / "out" / task["outputs"][0]).skeleton
        heights.append(round(float(out.rest_translation[out.index["Hips"], 1]), 6))
    assert heights == [0.982648, 0.882648]
