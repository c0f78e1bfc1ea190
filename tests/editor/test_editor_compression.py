"""The editor's compression: File > Export compressed's work and the comparison's preview."""
import warnings

import numpy as np
import pytest

import rigedit
from rigedit.compression import measure_error
from rigedit.editor.compression import CompressedExport, CompressedPreview, export_compressed
from rigedit.editor.document import Document
from rigedit.errors import RigFileError

BOUND = 1e-3   # 0.1 cm: loose enough to be quick, tight enough to mean something


@pytest.fixture(scope="module")
def rig():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rigedit.load_rig("quadruped")


@pytest.fixture
def doc(rig):
    d = Document(rig)
    d.set_current_clip("walk")
    return d


def test_export_rgc_holds_the_bound_when_read_back(doc, rig, tmp_path):
    out = tmp_path / "walk.rgc"
    report = export_compressed(doc, out, BOUND, clips=["walk"])
    assert out.is_file() and report.max_error <= BOUND
    back = rigedit.load_rig(out)
    assert list(back.clips) == ["walk"]
    err = measure_error(rig.skeleton, rig.clips["walk"], back.clips["walk"])
    assert err.max() <= BOUND * (1 + 1e-6)
    assert report.ratio > 1 and report.compressed_bytes <= out.stat().st_size


def test_export_glb_holds_the_bound_when_read_back(doc, rig, tmp_path):
    out = tmp_path / "quad.glb"
    report = export_compressed(doc, out, BOUND, clips=["run"])
    back = rigedit.load_rig(out)
    assert list(back.clips) == ["run"]
    err = measure_error(rig.skeleton, rig.clips["run"], back.clips["run"])
    assert err.max() <= BOUND * (1 + 1e-6) and report.max_error <= BOUND
    assert report.compressed_bytes > 0 and report.ratio > 1


def test_export_folder_holds_the_bound_with_mesh_and_skin(doc, rig, tmp_path):
    out = tmp_path / "quad"
    report = export_compressed(doc, out, BOUND, clips=["walk", "run"])
    back = rigedit.load_rig(out)
    assert sorted(back.clips) == ["run", "walk"] and len(back.vertices) == len(rig.vertices)
    for name in back.clips:
        err = measure_error(rig.skeleton, rig.clips[name], back.clips[name])
        assert err.max() <= BOUND * (1 + 1e-6)
    assert report.max_error <= BOUND and report.ratio > 1


@pytest.mark.parametrize("kwargs, words", [
    (dict(max_error=0.0), "max_error"), (dict(max_error=float("nan")), "max_error"),
    (dict(shell=-1.0), "shell"), (dict(clips=["gallop"]), "gallop"),
    (dict(path="x.fbx"), ".fbx"), (dict(meshopt=True), "meshopt")])
def test_bad_settings_are_refused_before_anything_is_written(doc, tmp_path, kwargs, words):
    settings = dict(path=tmp_path / "out.rgc", max_error=BOUND) | kwargs
    settings["path"] = tmp_path / settings["path"]
    with pytest.raises(ValueError, match=words.replace(".", r"\.")):
        CompressedExport(doc, **settings)
    assert list(tmp_path.iterdir()) == []


def test_a_failed_write_keeps_the_old_file(doc, tmp_path, monkeypatch):
    out = tmp_path / "walk.rgc"
    out.write_bytes(b"old")
    job = CompressedExport(doc, out, BOUND, clips=["walk"])
    import rigedit.io.atomic as atomic

    def broken(*a, **k):
        raise OSError("disk full")
    monkeypatch.setattr(atomic.os, "replace", broken)
    with pytest.raises(OSError):
        job.run()
    assert out.read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["walk.rgc"]


@pytest.mark.parametrize("name", ["run.glb", "run.rgc", "folder"])
def test_a_cancel_before_the_write_leaves_nothing(doc, tmp_path, name):
    from rigedit.progress import Cancelled

    def progress(fraction, stage=None):
        if stage == "write":
            raise Cancelled()
    with pytest.raises(Cancelled):
        export_compressed(doc, tmp_path / name, BOUND, clips=["run"], progress=progress)
    assert list(tmp_path.iterdir()) == []


def test_the_export_compresses_what_the_document_held_when_made(doc, tmp_path):
    clip = doc.rig.clips["walk"]
    tracks = dict(clip.tracks)
    job = CompressedExport(doc, tmp_path / "w.rgc", BOUND, clips=["walk"])
    clip.remove_track(*next(iter(tracks)))   # the user edits on while the job runs
    try:
        assert len(job.data.clips["walk"].tracks) == len(tracks)
        assert job.data.clips["walk"] is not clip
    finally:
        clip.tracks = tracks


def test_preview_errors_within_the_bound_and_at_follows_them(doc, rig):
    preview = CompressedPreview(doc, BOUND)
    entry = preview.refresh()
    f, j = preview.errors.shape
    assert j == len(rig.skeleton) and f == len(preview.times) > 10
    assert 0 < preview.errors.max() <= BOUND
    # at a checked frame, at() gives that frame's error and the compressed pose's joints
    k = int(np.argmax(preview.errors.max(axis=1)))
    pos, err = preview.at(preview.times[k])
    np.testing.assert_allclose(err, preview.errors[k], atol=1e-12)
    exact = entry.compressed.sample(preview.times[k])
    np.testing.assert_allclose(pos, rig.joint_matrices(exact)[:, :3, 3], atol=1e-9)
    original = rig.joint_matrices(rig.clips["walk"].sample(preview.times[k]))[:, :3, 3]
    gap = np.linalg.norm(pos - original, axis=1)
    assert np.all(gap <= err + 1e-12) and gap.max() > 0   # joints move less than their shell


def test_preview_cache_by_clip_revision_and_settings(doc):
    preview = CompressedPreview(doc, BOUND)
    first = preview.refresh()
    assert preview.refresh() is first and not preview.stale
    doc.set_current_clip("run")
    assert preview.stale
    run = preview.refresh()
    assert run is not first and run.original.name == "run"
    snap = preview.snapshot()
    clip = doc.rig.clips["run"]
    tracks = dict(clip.tracks)
    key = next(iter(tracks))
    clip.set_track(*key, tracks[key])   # an edit: a new revision
    try:
        assert preview.stale and not preview.accept(preview.compute(snap))
        assert preview.entry is run   # a result of before the edit is not taken
    finally:
        clip.tracks = tracks
    assert CompressedPreview(doc, BOUND / 2).key != preview.key


def test_preview_without_a_clip_says_so(rig):
    d = Document(rig)
    d.set_current_clip(None)
    with pytest.raises(ValueError, match="no clip"):
        CompressedPreview(d, BOUND).refresh()


def test_a_bound_no_encoding_reaches_names_the_file(doc, tmp_path):
    job = CompressedExport(doc, tmp_path / "w.rgc", 1e-12, clips=["head_nod"])
    with pytest.raises(RigFileError, match="w.rgc"):
        job.run()


def test_compressed_clips_open_read_only_and_play_their_bits(doc, tmp_path):
    from rigedit.compression import CompressedClip
    from rigedit.editor import files
    from rigedit.editor.compression import ReadOnlyCompressedClip

    out = tmp_path / "walk.rgc"
    export_compressed(doc, out, BOUND, clips=["walk"])
    plain = rigedit.load_rig(out).clips["walk"]
    clip = files.load_rig(out).clips["walk"]
    assert isinstance(clip, ReadOnlyCompressedClip) and isinstance(clip, CompressedClip)
    assert set(clip.tracks) == set(plain.to_clip().tracks)
    with pytest.raises(TypeError):
        clip.tracks[("root", "rotation")] = None   # the mapping is read-only
    for t in (0.0, 0.4, 1.1):
        np.testing.assert_array_equal(clip.sample(t).as_array(), plain.sample(t).as_array())
    before = clip.key_times()
    for edit in (lambda: clip.set_key("root", "rotation", 0.5, [0, 0, 0, 1]),
                 lambda: clip.state(), lambda: clip.set_duration(2.0)):
        with pytest.raises(ValueError, match="compressed"):
            edit()
    np.testing.assert_array_equal(clip.key_times(), before)
    duplicate = clip.copy("walk copy")   # Duplicate: a plain clip of the stored keys, editable
    assert not isinstance(duplicate, CompressedClip) and duplicate.name == "walk copy"
    np.testing.assert_allclose(duplicate.sample(0.4).as_array(), clip.sample(0.4).as_array(),
                               atol=1e-6)
    duplicate.set_key("root", "rotation", 0.5, [0, 0, 0, 1])


def test_timeline_key_edits_on_a_compressed_clip_are_one_message(doc, tmp_path):
    """The timeline's key buttons and key drags on a read-only compressed clip: each refusal
    reaches the error callback (one message), nothing changes and no undo step is made."""
    from rigedit.editor import files
    from rigedit.editor.timeline_keys import KeyEditor

    out = tmp_path / "walk.rgc"
    export_compressed(doc, out, BOUND, clips=["walk"])
    shown = Document(files.load_rig(out))
    shown.set_current_clip("walk")
    before = shown.clip.key_times().copy()
    messages = []
    editor = KeyEditor(shown, lambda: 30.0, lambda t: None, lambda: None, messages.append)
    shown.set_time(float(before[1]))
    assert editor.insert_key() == 0
    assert editor.delete_key() == 0
    assert editor.move_key(float(before[1]), float(before[1]) + 0.1) == 0
    editor.key_drag_start(float(before[1]), all_joints=True)
    editor.key_drag_move(float(before[1]) + 0.1)
    editor.key_drag_end()
    assert len(messages) == 4 and all("compressed" in m for m in messages)
    np.testing.assert_array_equal(shown.clip.key_times(), before)
    assert not shown.undo_stack.can_undo
