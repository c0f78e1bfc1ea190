"""io returns plain data: readers give a RigData with a typed meta, one registry names every
format, writers take the data, and Rig.from_data (above io) decides about weights."""
import ast
import shutil
import warnings

import numpy as np
import pytest

import rigedit
from builders import cylinder_rig, write_elk_folder
from rigedit import Rig, RigData, RigMeta
from rigedit.errors import RigFileError
from rigedit.io import WeightsComputedWarning
from rigedit.io.bvh import BvhUnitsWarning, read_bvh
from rigedit.io.gltf_read import read_gltf
from rigedit.io.load import read_rig
from rigedit.io.registry import FORMATS, RIG_FILE_SUFFIXES, format_of
from rigedit.io.rig_folder import read_rig_folder
from rigedit.io.save import save_rig
from testpaths import DATA, REPO


def _no_solve(*args, **kwargs):
    raise AssertionError("a reader computed weights")


def test_reading_a_folder_without_weights_starts_no_solve(tmp_path, monkeypatch):
    import rigedit.binding.weights as weights

    monkeypatch.setattr(weights, "compute_weights", _no_solve)
    folder = write_elk_folder(tmp_path / "elk")
    with warnings.catch_warnings():
        warnings.simplefilter("error", WeightsComputedWarning)
        data = read_rig_folder(folder)
    assert isinstance(data, RigData) and data.indices is None and data.weights is None
    assert data.meta.format == "folder" and data.meta.source == folder
    assert data.up == "z" and set(data.meta.clip_files) == set(data.clips) == {"bow"}
    assert data.vertices.shape == (31 * 24 + 2, 3) and data.faces.dtype == np.int64


def test_from_data_computes_missing_weights_in_the_open(tmp_path):
    data = read_rig_folder(write_elk_folder(tmp_path / "elk"))
    with pytest.warns(WeightsComputedWarning, match=r"elk: no weights file; computed weights "
                                                    r"\(idw\)"):
        rig = Rig.from_data(data, weights_method="idw")
    assert rig.weights_computed and rig.weights_method == "idw"
    assert rig.meta is data.meta and rig.path == data.meta.source
    assert rig.binding.indices.shape[0] == len(data.vertices)


def test_from_data_keeps_the_files_weights(tmp_path):
    folder = tmp_path / "cyl"
    cylinder_rig().save(folder)
    data = read_rig_folder(folder)
    assert data.indices is not None
    with warnings.catch_warnings():
        warnings.simplefilter("error", WeightsComputedWarning)
        rig = Rig.from_data(data)
    assert not rig.weights_computed
    np.testing.assert_array_equal(rig.binding.indices, data.indices)


def test_bvh_meta_says_what_was_decided():
    path = DATA / "bvh-cmu" / "131_01.bvh"
    if not path.is_file():
        pytest.skip(f"shared data not present: {path}")
    with pytest.warns(BvhUnitsWarning):
        guessed = read_bvh(path)
    meta = guessed.meta
    assert meta.format == "bvh" and meta.scale_guessed and meta.units.startswith("CMU")
    assert meta.scale == pytest.approx(0.0254 / 0.45)
    assert "CMU" in meta.notes["units"] and set(meta.rotation_orders) <= set(
        guessed.skeleton.names)
    given = read_bvh(path, scale=0.01).meta
    assert not given.scale_guessed and given.units is None and given.scale == 0.01
    rig = Rig.from_data(read_bvh(path, scale=0.01))
    assert rig.notes is rig.meta.notes and rig.source_rotation_orders == given.rotation_orders


def test_gltf_reads_as_data():
    path = DATA / "khronos-gltf" / "CesiumMan.glb"
    if not path.is_file():
        pytest.skip(f"shared data not present: {path}")
    data = read_gltf(path)
    assert data.meta.format == "gltf" and data.surface is not None
    assert data.indices.shape == data.weights.shape and len(data.indices) == len(data.vertices)


def test_every_format_is_one_registry_line(tmp_path):
    names = [f.name for f in FORMATS]
    assert names[:3] == ["folder", "gltf", "bvh"] and len(set(names)) == len(names)
    assert RIG_FILE_SUFFIXES[:3] == (".glb", ".gltf", ".bvh")
    assert len(set(RIG_FILE_SUFFIXES)) == len(RIG_FILE_SUFFIXES)   # one format per suffix
    for fmt in FORMATS:
        assert callable(fmt.read) and callable(fmt.write)
        for suffix in fmt.suffixes:
            assert format_of(tmp_path / f"a{suffix.upper()}") is fmt
    assert format_of(tmp_path).name == "folder"
    assert format_of(tmp_path / "new", role="write").name == "folder"
    (tmp_path / "a.obj").write_text("")
    with pytest.raises(RigFileError, match=r"expected a rig folder or a \.glb, \.gltf.* file, "
                                           r"got a \.obj file"):
        format_of(tmp_path / "a.obj")
    with pytest.raises(RigFileError, match=r"expected a folder or a \.glb, \.gltf.* file to "
                                           r"write, got a \.obj file"):
        format_of(tmp_path / "a.obj", role="write")


def test_read_rig_returns_data_and_load_rig_a_rig():
    data = read_rig("humanoid")
    assert isinstance(data, RigData) and data.indices is not None
    assert isinstance(rigedit.load_rig("humanoid"), Rig)
    from rigedit.io.load import load_rig

    assert isinstance(load_rig("humanoid"), Rig)   # the old io path still gives a rig


def test_writers_take_plain_data(tmp_path):
    rig = cylinder_rig()
    data = rig.data()
    assert data.skeleton is rig.skeleton and data.meta is rig.meta
    for name in ("c.glb", "c.bvh", "folder"):
        save_rig(data, tmp_path / name)
    back = read_rig(tmp_path / "c.glb")
    np.testing.assert_allclose(back.vertices, rig.vertices, atol=1e-6)
    folder = read_rig(tmp_path / "folder")
    np.testing.assert_array_equal(folder.faces, rig.faces)
    assert set(folder.clips) == {"bend"}


def test_a_copied_folder_keeps_its_clip_files_in_meta(tmp_path):
    shutil.copytree(REPO / "assets" / "humanoid", tmp_path / "h")
    data = read_rig(tmp_path / "h")
    assert {p.parent for p in data.meta.clip_files.values()} == {
        (tmp_path / "h" / "animations").resolve()}
    assert RigMeta().clip_files == {} and Rig.from_data(data).meta.clip_files is \
        data.meta.clip_files


IO = REPO / "rigedit" / "io"
ABOVE_IO = ("rig", "rigging", "binding", "editor", "cli", "render", "ui")


def _imports(path):
    """Absolute names of what a module of rigedit/io imports ("rigedit" for the root)."""
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level == 0:
                out.append(node.module)
                continue
            base = ["rigedit", "io"][:max(0, 3 - node.level)]
            module = ".".join(base + ([node.module] if node.module else []))
            out += [module] if node.module else [_from_package(module, a.name)
                                                  for a in node.names]
    return out


def _from_package(package, name):
    """``from package import name``: the submodule when there is one, else the package."""
    folder = REPO.joinpath(*package.split("."))
    is_module = (folder / f"{name}.py").is_file() or (folder / name).is_dir()
    return f"{package}.{name}" if is_module else package


@pytest.mark.parametrize("path", sorted(IO.glob("*.py")), ids=lambda p: p.name)
def test_io_imports_nothing_above_it(path):
    for name in _imports(path):
        parts = name.split(".")
        assert name != "rigedit" and not (parts[0] == "rigedit" and len(parts) > 1
                                          and parts[1] in ABOVE_IO), f"{path.name}: {name}"
