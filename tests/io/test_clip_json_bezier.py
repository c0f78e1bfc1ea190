"""Bezier tracks in rigedit's clip JSON: saved and loaded with every key field, and every
malformed entry one RigFileError naming the file."""
import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from builders import chain_skeleton
from rigedit.animation import Clip, Track
from rigedit.animation.curve import Curve
from rigedit.errors import RigFileError
from rigedit.io.clip_json import clip_to_dict, load_clip, save_clip


@pytest.fixture
def sk():
    return chain_skeleton(3)


@pytest.fixture
def clip(sk):
    times = np.arange(5) * 0.25
    quats = Rotation.from_rotvec(np.radians(90.0 * np.arange(5))[:, None] * [0, 0, 1]).as_quat()
    rot = Track("rotation", times, quats).with_interpolation("bezier")
    x = (Curve([0, 0.5, 1], [0, 2, 1]).with_interpolation([0], "linear")
         .with_handle(1, "right", (0.8, 3.0)).with_easing([2], "ease_in"))
    curves = (x, Curve([0.2], [1.0]), Curve([0, 1], [0, 1], "constant", right_type="vector"))
    rz = rot.curves[2].with_handle_type([1], "free").with_handle(1, "left", (0.1, 10.0))
    return Clip("b", sk, {("j1", "rotation"): Track.from_curves("rotation", rot.curves[:2] + (rz,),
                                                               "ZXY"),
                          ("j2", "translation"): Track.from_curves("translation", curves)})


def test_bezier_tracks_round_trip(tmp_path, clip):
    path = tmp_path / "b.json"
    save_clip(path, clip)
    back = load_clip(path, clip.skeleton)
    for key, tr in clip.tracks.items():
        got = back.tracks[key]
        assert got.interpolation == "bezier" and got.euler_order == tr.euler_order
        for a, b in zip(tr.curves, got.curves):
            for field in ("times", "values", "left", "right"):
                np.testing.assert_allclose(getattr(b, field), getattr(a, field), atol=1e-8)
            for field in ("interpolation", "left_type", "right_type"):
                assert list(getattr(b, field)) == list(getattr(a, field))
        ts = np.linspace(0, 1.2, 49)
        np.testing.assert_allclose([got.sample(t) for t in ts], [tr.sample(t) for t in ts],
                                   atol=1e-7)
    entry = clip_to_dict(clip)["tracks"][0]
    assert entry["euler_order"] == "ZXY" and "times" not in entry and len(entry["curves"]) == 3


def _broken(tmp_path, clip, edit):
    data = clip_to_dict(clip)
    edit(data["tracks"][1]["curves"][0])
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize("edit, message", [
    (lambda c: c.update(times=[0, 0.5, "x"]), "'times'"),
    (lambda c: c.update(times=[0, 1, 0.5]), "increasing"),
    (lambda c: c.update(times=[-1, 0.5, 1]), ">= 0"),
    (lambda c: c.update(values=[0, 1]), "'values'"),
    (lambda c: c.update(interpolation=["bezier", "cubic", "bezier"]), "'interpolation'"),
    (lambda c: c.update(left_type=["auto"]), "'left_type'"),
    (lambda c: c.update(right=[[0, 1], [2]]), "'right'"),
    (lambda c: c.update(left=[[0, 1e300], [0, 1], [0, 2]]), "'left'"),
    (lambda c: c.update(times=[]), "keys"),
    (lambda c: c.clear(), "'times'"),
])
def test_a_malformed_curve_is_one_error_naming_the_file(tmp_path, clip, edit, message):
    path = _broken(tmp_path, clip, edit)
    with pytest.raises(RigFileError, match=message) as info:
        load_clip(path, clip.skeleton)
    assert str(path) in str(info.value) and "j2" in str(info.value)


def test_a_track_without_three_curves_or_with_a_bad_order(tmp_path, clip):
    for edit, message in ((lambda e: e["curves"].pop(), "3 curves"),
                          (lambda e: e.update(curves="xyz"), "curves"),
                          (lambda e: e.update(euler_order="XXY"), "euler_order")):
        data = clip_to_dict(clip)
        edit(data["tracks"][0])
        path = tmp_path / "bad.json"
        path.write_text(json.dumps(data))
        with pytest.raises(RigFileError, match=message):
            load_clip(path, clip.skeleton)


def test_a_rig_folder_keeps_bezier_tracks(tmp_path):
    import rigedit
    from builders import cylinder_rig
    from rigedit.io.rig_save import save_rig_folder_atomic
    rig = cylinder_rig()
    clip = rig.clips["bend"]
    bent = clip.tracks[("j1", "rotation")].with_interpolation("bezier")
    curves = list(bent.curves)
    curves[2] = curves[2].with_easing([1], "ease_in_out")
    clip.set_track("j1", "rotation", Track.from_curves("rotation", curves))
    save_rig_folder_atomic(tmp_path / "rig", rig)
    back = rigedit.load_rig(tmp_path / "rig").clips["bend"]
    got = back.tracks[("j1", "rotation")]
    assert got.interpolation == "bezier" and list(got.curves[2].left_type) == list(
        curves[2].left_type)
    for t in np.linspace(0, 1, 21):
        a, b = clip.sample(t).rotation, back.sample(t).rotation
        np.testing.assert_allclose(np.abs(np.sum(a * b, axis=1)), 1, atol=1e-9)
