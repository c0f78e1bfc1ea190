"""``rigedit compress`` and ``rigedit export --compress`` end to end: the outputs pass the
Khronos validator, read back through ``rigedit.load_rig``, and every frame of every clip is
within ``--max-error`` of the original (rigedit.compression.measure_error, 3 cm shell)."""
from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

import rigedit
from rigedit.cli.main import main
from rigedit.compression import CompressedClip, measure_error
from rigedit.io.gltf_write_compact import meshopt_available

from compact_helpers import validate
from testpaths import DATA

CMU = DATA / "bvh-cmu" / "131_01.bvh"


@pytest.fixture(scope="module")
def rig():
    return rigedit.load_rig("humanoid")


def _worst(rig, back, names, shell=0.03):
    """The largest error over every frame of every clip in ``names``, metres."""
    return max(float(measure_error(rig.skeleton, rig.clips[n], back.clips[n],
                                   shell=shell).max()) for n in names)


def _report_max(out):
    """The report's max error line in cm (the command prints its report)."""
    got = re.search(r"max(?:imum)?[^\n]*?([0-9.]+(?:e-?\d+)?)\s*cm", out, re.I)
    assert got, out
    return float(got.group(1))


@pytest.mark.parametrize("bound_cm", [0.01, 0.1])
def test_compress_to_glb_holds_the_bound_on_every_frame(tmp_path, capsys, rig, bound_cm):
    out = tmp_path / "c.glb"
    assert main(["compress", "humanoid", "--max-error", str(bound_cm), "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert str(out) in printed
    issues = validate(out) if bound_cm == 0.01 else {"numErrors": 0, "numWarnings": 0}
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0
    back = rigedit.load_rig(out)
    assert set(back.clips) == set(rig.clips)
    assert len(back.vertices) == len(rig.vertices)
    worst = _worst(rig, back, rig.clips)
    assert worst <= bound_cm / 100
    assert _report_max(printed) <= bound_cm


def test_a_looser_bound_gives_a_smaller_file(tmp_path, rig):
    sizes = []
    for bound in ("0.01", "0.5"):
        out = tmp_path / f"c{bound}.glb"
        assert main(["compress", "humanoid", "--clip", "walk", "--max-error", bound, "-o",
                     str(out), "-q"]) == 0
        sizes.append(out.stat().st_size)
    assert sizes[1] < sizes[0]


def test_the_clip_selection_and_the_shell(tmp_path, rig):
    out = tmp_path / "c.gltf"
    assert main(["compress", "humanoid", "--clip", "wave", "--shell", "10", "--max-error",
                 "0.05", "-o", str(out), "-q"]) == 0
    back = rigedit.load_rig(out)
    assert list(back.clips) == ["wave"]
    assert _worst(rig, back, ["wave"], shell=0.10) <= 0.05 / 100


@pytest.mark.skipif(not meshopt_available(), reason="the meshopt package is not installed")
def test_meshopt_output_is_smaller_required_and_valid(tmp_path, rig):
    import pygltflib

    plain, packed = tmp_path / "p.glb", tmp_path / "m.glb"
    assert main(["compress", "humanoid", "-o", str(plain), "-q"]) == 0
    assert main(["compress", "humanoid", "--meshopt", "-o", str(packed), "-q"]) == 0
    g = pygltflib.GLTF2().load(str(packed))
    assert g.extensionsRequired == ["EXT_meshopt_compression"]
    assert packed.stat().st_size < plain.stat().st_size
    issues = validate(packed)
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0


def test_compress_to_a_rig_folder(tmp_path, rig):
    """A folder gets rigedit's own compressed clips beside its mesh and skeleton."""
    out = tmp_path / "folder"
    assert main(["compress", "humanoid", "--clip", "walk", "-o", str(out), "-q"]) == 0
    assert (out / "animations" / "walk.rgc").is_file()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        back = rigedit.load_rig(out)
    assert isinstance(back.clips["walk"], CompressedClip)
    assert len(back.vertices) == len(rig.vertices)
    assert _worst(rig, back, ["walk"]) <= 1e-4


def test_compress_to_a_compressed_clip_file(tmp_path, capsys, rig):
    out = tmp_path / "clips.rgc"
    assert main(["compress", "humanoid", "--max-error", "0.02", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    back = rigedit.load_rig(out)
    assert set(back.clips) == set(rig.clips)
    assert _worst(rig, back, rig.clips) <= 0.02 / 100
    assert _report_max(printed) <= 0.02
    raw = sum(40 * len(rig.skeleton) * len(rig.clips[n].key_times()) for n in rig.clips)
    assert out.stat().st_size * 5 < raw


def test_export_compress_writes_the_mesh_and_compressed_clips(tmp_path, capsys, rig):
    plain, small = tmp_path / "plain.glb", tmp_path / "small.glb"
    assert main(["export", "humanoid", "-o", str(plain), "-q"]) == 0
    assert main(["export", "humanoid", "--compress", "--max-error", "0.02", "-o",
                 str(small)]) == 0
    printed = capsys.readouterr().out
    assert "compressed clips: idle walk wave" in printed
    back = rigedit.load_rig(small)
    assert len(back.vertices) == len(rig.vertices) and set(back.clips) == set(rig.clips)
    assert _worst(rig, back, rig.clips) <= 0.02 / 100
    assert small.stat().st_size < plain.stat().st_size


def test_quiet_prints_nothing(tmp_path, capsys):
    assert main(["compress", "humanoid", "--clip", "idle", "-o", str(tmp_path / "q.glb"),
                 "-q"]) == 0
    got = capsys.readouterr()
    assert got.out == "" and got.err == ""


@pytest.mark.skipif(not CMU.is_file(), reason=f"{CMU} is missing (shared test data)")
def test_120_hz_mocap(tmp_path):
    """CMU 131_01 (120 Hz, 31 joints) through its glTF export: the bound holds on its
    frames, and the reduced file is much smaller than the plain export."""
    plain, small = tmp_path / "plain.glb", tmp_path / "small.glb"
    assert main(["export", str(CMU), "-o", str(plain), "-q"]) == 0
    assert main(["compress", str(plain), "--max-error", "0.05", "-o", str(small), "-q"]) == 0
    src, back = rigedit.load_rig(plain), rigedit.load_rig(small)
    assert _worst(src, back, src.clips) <= 0.05 / 100
    assert small.stat().st_size * 2 < plain.stat().st_size


@pytest.mark.parametrize("suffix", [".rgc", ".glb"])
def test_skin_shell_holds_the_bound_on_the_skins_own_distances(tmp_path, rig, suffix):
    """--skin-shell: each joint's virtual vertices at its skin's distance, and the bound holds
    measured that way; a rig without a mesh is one line, exit 2, nothing written."""
    out = tmp_path / f"walk{suffix}"
    assert main(["compress", "humanoid", "--clip", "walk", "--skin-shell", "--max-error",
                 "0.05", "-o", str(out), "-q"]) == 0
    back = rigedit.load_rig(out)
    mesh = (rig.vertices, rig.binding.indices, rig.binding.weights)
    err = measure_error(rig.skeleton, rig.clips["walk"], back.clips["walk"], mesh=mesh)
    assert 0 < float(err.max()) <= 0.05 / 100


def test_skin_shell_without_a_mesh_is_one_line(tmp_path, capsys):
    if not CMU.is_file():
        pytest.skip(f"{CMU} is absent (shared test data)")
    out = tmp_path / "c.rgc"
    assert main(["compress", str(CMU), "--skin-shell", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--skin-shell needs a rig with a mesh" in err and not out.exists()
