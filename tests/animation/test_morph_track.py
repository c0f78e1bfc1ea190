"""Weight tracks (one morph target's weight over time) and a clip's weight tracks."""
import numpy as np
import pytest

from builders import chain_skeleton
from rigedit.animation.clip import Clip
from rigedit.animation.morph_track import WeightTrack


def test_linear_and_step_sample_between_keys_and_clamp():
    tr = WeightTrack([1.0, 0.0, 2.0], [1.0, 0.0, 0.5])      # sorted on construction
    assert list(tr.times) == [0.0, 1.0, 2.0]
    assert tr.sample(0.25) == pytest.approx(0.25)
    assert tr.sample(1.5) == pytest.approx(0.75)
    assert tr.sample(-1.0) == 0.0 and tr.sample(9.0) == 0.5
    step = WeightTrack([0.0, 1.0], [0.2, 0.8], "step")
    assert step.interpolation == "STEP"
    assert step.sample(0.99) == 0.2 and step.sample(1.0) == 0.8


def test_cubicspline_is_gltf_hermite_with_the_file_tangents():
    times, values = [0.0, 2.0], [0.0, 1.0]
    tr = WeightTrack(times, values, "CUBICSPLINE", in_tangents=[0.0, 3.0],
                     out_tangents=[0.5, 0.0])
    # glTF: p(t) = (2t^3-3t^2+1) v0 + (t^3-2t^2+t) td b0 + (-2t^3+3t^2) v1 + (t^3-t^2) td a1
    u, td = 0.3, 2.0
    want = ((2 * u**3 - 3 * u**2 + 1) * 0.0 + (u**3 - 2 * u**2 + u) * td * 0.5
            + (-2 * u**3 + 3 * u**2) * 1.0 + (u**3 - u**2) * td * 3.0)
    assert tr.sample(0.6) == pytest.approx(want, abs=1e-12)


@pytest.mark.parametrize("times, values, mode", [
    ([], [], "LINEAR"), ([0, 0], [1, 2], "LINEAR"), ([0, np.nan], [1, 2], "LINEAR"),
    ([0, 1], [1, np.inf], "LINEAR"), ([0, 1], [1], "LINEAR"), ([0, 1], [0, 1], "slerp")])
def test_bad_keys_are_refused(times, values, mode):
    with pytest.raises(ValueError):
        WeightTrack(times, values, mode)


def test_edits_return_new_tracks_and_keep_the_spline_tangents():
    tr = WeightTrack([0.0, 1.0], [0.0, 1.0], "CUBICSPLINE", [0.0, 7.0], [5.0, 0.0])
    keyed = tr.with_key(0.5, 0.25)
    assert len(tr) == 2 and len(keyed) == 3
    assert keyed.out_tangents[0] == 5.0 and keyed.in_tangents[2] == 7.0
    assert keyed.with_key(0.5, 0.75).values[1] == 0.75            # replaces, not adds
    assert len(keyed.without_keys([0.5])) == 2
    assert tr.without_keys([0.0, 1.0]) is None
    moved = keyed.with_moved_keys({0.5: 2.0})
    assert list(moved.times) == [0.0, 1.0, 2.0] and moved.values[2] == 0.25
    assert tr.with_moved_keys({3.0: 4.0}) is tr


def test_clip_samples_weights_counts_them_in_duration_and_undoes():
    sk = chain_skeleton(2)
    clip = Clip("c", sk, morph_tracks={"smile": WeightTrack([0.0, 4.0], [0.0, 1.0])})
    assert clip.duration == 4.0
    assert clip.sample_morphs(1.0) == {"smile": pytest.approx(0.25)}
    before = clip.state()
    clip.set_morph_key("blink", 2.0, 1.0)
    assert set(clip.sample_morphs(2.0)) == {"smile", "blink"}
    assert 2.0 in clip.key_times() and list(clip.morph_key_times("blink")) == [2.0]
    clip.restore(before)
    assert set(clip.morph_tracks) == {"smile"}
    assert clip.delete_keys([4.0]) == 1 and len(clip.morph_tracks["smile"]) == 1
    assert clip.delete_keys([0.0], joints=[sk.names[0]]) == 0    # a joint edit spares weights
    copy = clip.copy("d")
    assert copy.morph_tracks["smile"] is not clip.morph_tracks["smile"]
    assert Clip("e", sk).sample_morphs(0.0) == {}


# ---------------------------------------------------------------------- rigedit clip JSON
import json  # noqa: E402

from rigedit.errors import RigFileError  # noqa: E402
from rigedit.io.clip_json import load_clip, save_clip  # noqa: E402


def test_clip_json_round_trips_weight_tracks_of_every_mode(tmp_path):
    sk = chain_skeleton(2)
    clip = Clip("face", sk, morph_tracks={
        "smile": WeightTrack([0.0, 0.5, 1.0], [0.0, 1.0, 0.2]),
        "blink": WeightTrack([0.0, 1.0], [1.0, 0.0], "STEP"),
        "jaw": WeightTrack([0.0, 2.0], [0.0, 1.0], "CUBICSPLINE", [0.1, 0.2], [0.3, 0.4])})
    path = tmp_path / "face.json"
    save_clip(path, clip)
    back = load_clip(path, sk)
    assert set(back.morph_tracks) == {"smile", "blink", "jaw"}
    assert back.duration == 2.0
    for t in np.linspace(0, 2, 17):
        for name, w in clip.sample_morphs(t).items():
            assert back.sample_morphs(t)[name] == pytest.approx(w, abs=1e-9)
    assert list(back.morph_tracks["jaw"].out_tangents) == [0.3, 0.4]
    # a clip without weight tracks writes none (files stay as before)
    save_clip(path, Clip("plain", sk))
    assert "morph_tracks" not in json.loads(path.read_text())


@pytest.mark.parametrize("entry, words", [
    ({"times": [0], "values": [1]}, "'target'"),
    ({"target": "a", "times": [0, 1], "values": [1]}, "'values'"),
    ({"target": "a", "times": [-1], "values": [1]}, ">= 0"),
    ({"target": "a", "times": [0, 0], "values": [1, 2]}, "two keys"),
    ({"target": "a", "times": [0], "values": [1], "interpolation": "slerp"}, "interpolation"),
    ({"target": "", "times": [0], "values": [1]}, "non-empty"),
    ({"target": "a", "times": [0], "values": ["x"]}, "'values'")])
def test_malformed_weight_tracks_are_one_error_naming_the_file(tmp_path, entry, words):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"tracks": [], "morph_tracks": [entry]}))
    with pytest.raises(RigFileError, match=words) as err:
        load_clip(path, chain_skeleton(2))
    assert "bad.json" in str(err.value)
