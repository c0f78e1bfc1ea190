"""Adversarial plans: outputs that would collide with each other or with the batch's own
files (the manifest folder, the thumbnails, the report), names too long for a file."""
from pathlib import Path

from rigedit.batch.tasks import RESERVED, check_options, plan


def _outputs(tasks):
    return [o for t in tasks for o in t["outputs"]]


def test_two_targets_with_one_name_do_not_share_an_output(tmp_path):
    # x/hero.glb and y/hero.glb: both tasks of walk.bvh wrote walk__hero.glb
    a, b = tmp_path / "x" / "hero.glb", tmp_path / "y" / "hero.glb"
    for p in (a, b):
        p.parent.mkdir()
        p.write_text("x")
    settings = check_options("retarget", {"to": [str(a), str(b)]})
    tasks = plan("retarget", [tmp_path / "walk.bvh", tmp_path / "run.bvh"], tmp_path, settings)
    outs = _outputs(tasks)
    assert len(tasks) == 4 and len(set(outs)) == 4
    assert all(o.startswith(("walk__hero-", "run__hero-")) for o in outs)


def test_an_input_named_like_the_manifest_or_the_thumbnails_gets_its_own_name(tmp_path):
    inputs = [tmp_path / "in" / n for n in ("manifest.glb", "thumbs.glb", "report.html.glb",
                                     "manifest.json.bvh", "walk.glb")]
    for job, options in (("convert", {"to": "folder"}), ("convert", {"to": "glb"}),
                         ("autorig", {"format": "folder"})):
        tasks = plan(job, inputs, tmp_path, check_options(job, options))
        tops = [Path(o).parts[0] for o in _outputs(tasks)]
        assert not set(tops) & RESERVED, (job, tops)
        assert len(set(tops)) == len(tops)
        assert tasks[-1]["outputs"][0] in ("walk", "walk.glb")   # an ordinary name stays


def test_a_long_name_is_cut_to_fit_a_file_name(tmp_path):
    motion = tmp_path / ("歩く" * 40 + ".bvh")   # 240 bytes
    target = tmp_path / ("走る" * 40 + ".glb")
    target.write_text("x")
    tasks = plan("retarget", [motion], tmp_path,
                 check_options("retarget", {"to": [str(target)]}))
    name = tasks[0]["outputs"][0]
    assert len(name.encode()) <= 200 and name.endswith(".glb") and name.startswith("歩く")
    # the writers' temporary name beside it fits too (255 bytes)
    assert len(f".{name}.pid4194304-abcdefgh.tmp".encode()) <= 255


def test_a_render_clip_with_a_slash_stays_in_outdir(tmp_path):
    tasks = plan("render", [tmp_path / "hero.glb"], tmp_path,
                 check_options("render", {"clip": "Take 001/../../run"}))
    assert all("/" not in o for o in tasks[0]["outputs"])


def test_an_output_over_an_input_is_refused_before_any_work(tmp_path):
    # `rigedit batch compress *.glb -o .` wrote each lossy result over its original
    import pytest

    from rigedit.batch.inputs import BatchUsageError

    hero = tmp_path / "hero.glb"
    hero.write_text("x")
    for job, options in (("compress", {"max_error": 1.0}), ("convert", {"to": "glb"})):
        with pytest.raises(BatchUsageError, match="hero.glb: a task would write its output"):
            plan(job, [hero], tmp_path, check_options(job, options))
    # through a symlinked OUTDIR too
    (tmp_path / "link").symlink_to(tmp_path)
    with pytest.raises(BatchUsageError, match="over this input"):
        plan("convert", [hero], tmp_path / "link", check_options("convert", {"to": "glb"}))
    # into another folder, or to another suffix, it is fine
    assert plan("convert", [hero], tmp_path, check_options("convert", {"to": "bvh"}))


def test_many_inputs_of_one_name_never_share_an_output(tmp_path):
    # the 6-digit tag is 24 bits: 20,000 folders each with a take.bvh gave 10 pairs of tasks
    # one output name, each pair's second overwriting the first's
    import hashlib
    import time
    from collections import Counter

    # fixed paths (nothing is read): the same 10 pairs every time
    srcs = [Path(f"/library/d{i:05d}/take.bvh") for i in range(20000)]
    t0 = time.perf_counter()
    tasks = plan("convert", srcs, Path("/library-out"), check_options("convert", {"to": "glb"}))
    took = time.perf_counter() - t0
    outs = _outputs(tasks)
    assert len(set(outs)) == len(outs) == 20000
    short = Counter(hashlib.sha1(str(s).encode()).hexdigest()[:6] for s in srcs)
    agree = sum(n for n in short.values() if n > 1)
    assert agree >= 2   # the case happens here
    assert sum(len(o) > len("take-123456.glb") for o in outs) == agree   # those lengthened
    assert len({t["id"] for t in tasks}) == 20000
    assert took < 30   # no quadratic step (about 1 s here)


def test_two_task_ids_that_agree_get_longer_digests(tmp_path, monkeypatch):
    # 10 hex digits are 40 bits: a million tasks make a pair likely; a pair shared one
    # manifest entry and one Dask key
    from rigedit.batch import tasks as tasks_module
    from rigedit.batch.manifest import task_id

    monkeypatch.setattr(tasks_module, "task_id", lambda job, s, t=None, digits=10:
                        "noop-x-0000000000" if digits == 10 else task_id(job, s, t, digits))
    got = plan("noop", [tmp_path / "a.bvh", tmp_path / "b.bvh"], tmp_path,
               check_options("noop", {}))
    ids = [t["id"] for t in got]
    assert len(set(ids)) == 2 and all(len(i.rsplit("-", 1)[1]) == 40 for i in ids)


def test_names_one_file_on_a_case_insensitive_share_get_their_own_outputs(tmp_path):
    # Walk.bvh and walk.bvh (or é composed and decomposed) wrote Walk.glb and walk.glb:
    # one file on macOS, Windows or an SMB share, where the second overwrote the first
    import unicodedata

    srcs = [tmp_path / n for n in ("Walk.bvh", "walk.bvh", "caf\u00e9.bvh", "cafe\u0301.bvh",
                                   "Manifest.glb", "run.bvh")]
    tasks = plan("convert", srcs, tmp_path / "out", check_options("convert", {"to": "folder"}))
    outs = [unicodedata.normalize("NFC", o).casefold() for o in _outputs(tasks)]
    assert len(set(outs)) == len(outs) and "manifest" not in outs
    assert _outputs(tasks)[-1] == "run"


def test_every_output_name_and_its_temporary_fit_a_file_name(tmp_path):
    # a render's clip name came on top of a 160-byte base, and the whole 40-digit tag on
    # top of a cut one: names over 255 bytes, whose writes fail
    long_a = tmp_path / "a" / ("é" * 150 + ".glb")
    long_b = tmp_path / "b" / ("é" * 150 + ".glb")
    for job, options in (("render", {"clip": "x" * 300}), ("convert", {"to": "glb"})):
        tasks = plan(job, [long_a, long_b], tmp_path / "out", check_options(job, options))
        for name in _outputs(tasks):
            assert len(f".{name}.pid4194304-abcdefgh.tmp".encode()) <= 255, name
    # the whole tag too (forced: two tasks whose short tags agree)
    from rigedit.batch import tasks as tasks_module

    assert len(tasks_module._tagged("é" * 150, "f" * 40).encode()) <= \
        tasks_module.MAX_BASE_BYTES
