from testpaths import REPO
import numpy as np
import pytest

from builders import cylinder
from rigedit.errors import RigFileError
from rigedit.io.mesh import load_mesh, save_obj


def test_obj_round_trip_and_polygon_triangulation(tmp_path):
    v, f = cylinder(rings=4, segments=6)
    save_obj(tmp_path / "c.obj", v, f)
    v2, f2 = load_mesh(tmp_path / "c.obj")
    assert np.allclose(v2, v, atol=1e-6) and np.array_equal(f2, f)
    quad = tmp_path / "q.obj"
    quad.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1 4/1\n")
    _, fq = load_mesh(quad)
    assert fq.tolist() == [[0, 1, 2], [0, 2, 3]]


def test_obj_seam_duplicates_are_welded(tmp_path):
    p = tmp_path / "seam.obj"
    p.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 4 5 3\n")
    v, f = load_mesh(p)
    assert len(v) == 4
    assert f[1, 0] == f[0, 1]  # the duplicated (1,0,0) became one vertex
    v_raw, _ = load_mesh(p, weld=False)
    assert len(v_raw) == 5


def test_ply_and_stl_through_meshio(tmp_path):
    import meshio

    v, f = cylinder(rings=3, segments=5)
    for ext in ("ply", "stl", "vtk"):
        # Binary files: meshio's ASCII-STL sniffing overflows on its own ASCII output.
        meshio.write_points_cells(tmp_path / f"m.{ext}", v, [("triangle", f)], binary=True)
        v2, f2 = load_mesh(tmp_path / f"m.{ext}")
        assert len(f2) == len(f)
        assert np.allclose(np.sort(v2, axis=0), np.sort(v, axis=0), atol=1e-5)


@pytest.mark.parametrize("text,msg", [
    ("v 0 0\nf 1 2 3\n", "line 1: expected 'v x y z'"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "face index out of range"),
    ("v 0 0 0\nf a b c\n", "line 2: expected face indices"),
    ("v 0 0 0\nv 1 0 0\nf 1 2\n", "a face needs 3 vertices"),
    ("# nothing\n", "no faces"),
])
def test_malformed_obj_names_file_and_problem(tmp_path, text, msg):
    p = tmp_path / "bad.obj"
    p.write_text(text)
    with pytest.raises(RigFileError, match=msg) as err:
        load_mesh(p)
    assert str(p) in str(err.value)


def test_missing_and_unknown_format(tmp_path):
    with pytest.raises(RigFileError, match="file not found"):
        load_mesh(tmp_path / "nope.obj")
    (tmp_path / "x.fbx").write_text("x")
    with pytest.raises(RigFileError, match=r"expected a mesh file .* got \.fbx"):
        load_mesh(tmp_path / "x.fbx")


def test_real_models_load():
    from pathlib import Path

    data = REPO.parent / "shared" / "data" / "common-3d-test-models"
    if not data.is_dir():
        pytest.skip("shared test data not present")
    v, f = load_mesh(data / "homer.obj")
    assert len(v) > 1000 and f.max() < len(v)
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert np.all(counts == 2)  # closed and manifold as SOURCES.md says
