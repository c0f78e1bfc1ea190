"""Dispatch of load_rig / save_rig by path type."""
import numpy as np
import pytest

import rigedit
from builders import cylinder_rig
from rigedit.cli.main import main
from rigedit.errors import RigFileError
from rigedit.io.load import rig_kind


def test_kind_by_suffix_and_folder(tmp_path):
    assert rig_kind(tmp_path / "a.GLB") == "gltf"
    assert rig_kind(tmp_path / "a.gltf") == "gltf"
    assert rig_kind(tmp_path / "a.bvh") == "bvh"
    assert rig_kind(tmp_path) == "folder"


def test_unknown_file_kind_names_file_and_kinds(tmp_path):
    path = tmp_path / "model.3ds"
    path.write_text("x")
    with pytest.raises(RigFileError, match=r"model\.3ds.*\.glb, \.gltf, \.bvh, \.fbx or \.rgc"):
        rigedit.load_rig(path)


def test_missing_rig_file_is_not_found(tmp_path):
    with pytest.raises(RigFileError, match=r"walk\.bvh: expected a file, got nothing"):
        rigedit.load_rig(tmp_path / "walk.bvh")


def test_scale_refused_for_a_folder(tmp_path):
    rig = cylinder_rig()
    rig.save(tmp_path / "cyl")
    with pytest.raises(RigFileError, match="only with a .bvh"):
        rigedit.load_rig(tmp_path / "cyl", scale=0.01)


def test_save_folder_round_trip_through_dispatch(tmp_path):
    rig = cylinder_rig()
    rigedit.save_rig(rig, tmp_path / "out")
    back = rigedit.load_rig(tmp_path / "out")
    assert np.allclose(back.vertices, rig.vertices)
    assert sorted(back.clips) == ["bend"]


def test_save_unknown_extension_and_unknown_clip(tmp_path):
    rig = cylinder_rig()
    with pytest.raises(RigFileError, match=r"x\.3ds.*\.3ds file"):
        rig.save(tmp_path / "x.3ds")
    with pytest.raises(RigFileError, match="'nope'"):
        rig.save(tmp_path / "x.bvh", clips=["nope"])


def test_cli_export_folder(tmp_path, capsys):
    rig = cylinder_rig()
    rig.save(tmp_path / "cyl")
    assert main(["export", str(tmp_path / "cyl"), "-o", str(tmp_path / "copy")]) == 0
    assert "clips: bend" in capsys.readouterr().out
    assert sorted(rigedit.load_rig(tmp_path / "copy").clips) == ["bend"]
