"""Adversarial inputs to the compressed outputs and the command: a clip entirely at its rest
(glTF), bounds that round to nothing in metres or that no encoding reaches."""
import dataclasses
import json

import numpy as np
import pytest

import rigedit
from rigedit.animation import Clip, Track
from rigedit.cli.main import main
from rigedit.compression import measure_error


@pytest.fixture(scope="module")
def humanoid():
    return rigedit.load_rig("humanoid")


def _glb_json(path):
    data = path.read_bytes()
    length = int.from_bytes(data[12:16], "little")
    return json.loads(data[20:20 + length])


def test_a_clip_at_its_rest_is_not_lost_in_gltf(tmp_path, humanoid):
    """Every channel of every clip at the rest used to give animations without a channel,
    which the writer left out: the command said it wrote the clip, the file had none. Each
    clip now keys the root's rotation at the rest and keeps its duration."""
    sk = humanoid.skeleton
    still = Clip("still", sk, {(sk.names[3], "rotation"): Track(
        "rotation", [0.0, 1.0], [sk.rest_rotation[3]] * 2)}, 2.0)
    hold = Clip("hold", sk, {}, 1.5)
    data = dataclasses.replace(humanoid.data(), clips={"still": still, "hold": hold})
    out = tmp_path / "still.glb"
    from rigedit.io.gltf_compress import save_gltf_compressed_rig

    report = save_gltf_compressed_rig(data, out)
    doc = _glb_json(out)
    assert sorted(a["name"] for a in doc["animations"]) == ["hold", "still"]
    assert all(len(a["channels"]) >= 1 for a in doc["animations"])
    back = rigedit.load_rig(out)
    assert set(back.clips) == {"still", "hold"}
    assert back.clips["still"].duration == pytest.approx(2.0)
    assert back.clips["hold"].duration == pytest.approx(1.5)
    for name, clip in (("still", still), ("hold", hold)):
        assert measure_error(sk, clip, back.clips[name]).max() <= 1e-6
    assert report.max_error <= 1e-4


@pytest.mark.parametrize("option", ["--max-error", "--shell"])
def test_a_bound_that_is_zero_in_metres_is_one_line(tmp_path, capsys, option):
    """5e-324 cm passes a "positive centimetres" check but is 0 m: the rgc path used to say
    "got 0.0" from the library and the glTF one "cannot hold max_error 0 m" after compressing.
    Now the option is refused before the rig is read."""
    out = tmp_path / "o.rgc"
    assert main(["compress", "humanoid", option, "5e-324", "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and option in err[0]
    assert not out.exists()


@pytest.mark.parametrize("suffix", [".rgc", ".glb", ""])
def test_an_unreachable_bound_names_the_output(tmp_path, capsys, suffix):
    """1e-7 cm no encoding reaches: one line naming the output (the .rgc and folder outputs
    did not name any file), exit 2, nothing written."""
    out = tmp_path / f"o{suffix}"
    assert main(["compress", "humanoid", "--clip", "walk", "--max-error", "1e-7", "-o",
                 str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(out) in err[0] and "cannot hold" in err[0]
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []
