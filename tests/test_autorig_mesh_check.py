"""rigging.mesh_check: what an auto-rigged mesh may be, and the one error otherwise."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import ConvexHull

import rigedit
from rigedit.errors import RigFileError
from rigedit.io.mesh import save_obj
from rigedit.rigging.mesh_check import MAX_HOLE, check_mesh, read_mesh

CESIUM = Path(__file__).resolve().parents[2] / "shared" / "data" / "khronos-gltf" / \
    "CesiumMan.glb"


@pytest.fixture(scope="module")
def body():
    rig = rigedit.load_rig("humanoid")
    return rig.vertices, rig.faces


def _sphere(n=300, centre=(0, 0, 0), radius=1.0, seed=0):
    p = np.random.default_rng(seed).normal(size=(n, 3))
    p = p / np.linalg.norm(p, axis=1, keepdims=True)
    return p * radius + centre, ConvexHull(p).simplices


def test_closed_mesh_passes(body):
    c = check_mesh(*body, "human.obj")
    assert c.holes == [] and c.nonmanifold == 0 and c.part_shares == [pytest.approx(1.0)]
    assert c.body.all()
    assert "holes: closed (no holes)" in c.lines()


def test_small_holes_pass_and_are_reported(body):
    v, f = body
    centres = v[f].mean(axis=1)
    # open the crown of the head: a hole a few centimetres across
    top = np.argsort(-centres[:, 1])[:30]
    keep = np.ones(len(f), dtype=bool)
    keep[top] = False
    c = check_mesh(v, f[keep], "human.obj")
    assert len(c.holes) == 1 and 0 < c.holes[0] < MAX_HOLE
    assert c.lines()[1] == f"holes: 1 hole, the largest {100 * c.holes[0]:.1f}% of the size across"


def test_big_hole_is_one_error_naming_the_file(body):
    v, f = body
    keep = v[f].mean(axis=1)[:, 2] > 0.0        # the front half only
    with pytest.raises(RigFileError) as err:
        check_mesh(v, f[keep], "front.obj")
    msg = str(err.value)
    assert msg.startswith("front.obj: 1 hole, the largest ")
    assert "auto-rigging needs a closed mesh or nearly" in msg


def test_small_parts_ride_along_outside_the_embedding(body):
    v, f = body
    eye, eye_f = _sphere(60, centre=(0.03, 1.65, 0.1), radius=0.01)
    big, big_f = _sphere(300, centre=(2.0, 1.0, 0.0), radius=0.4, seed=1)
    verts = np.vstack([v, eye, big])
    faces = np.vstack([f, eye_f + len(v), big_f + len(v) + len(eye)])
    c = check_mesh(verts, faces, "parts.obj")
    assert len(c.part_shares) == 3
    # the eye is left out of the embedding, the big ball (over 1% of the area) is not
    assert c.body.sum() == len(f) + len(big_f)
    assert "3 parts" in c.lines()[3] and "1 small ones" in c.lines()[3]


def test_scatter_of_pieces_and_soup_are_errors():
    pieces = [_sphere(20, centre=(3.0 * i, 0, 0), radius=1.0, seed=i) for i in range(12)]
    v = np.vstack([p[0] for p in pieces])
    f = np.vstack([p[1] + 20 * i for i, p in enumerate(pieces)])
    with pytest.raises(RigFileError, match=r"scatter.obj: 12 separate pieces, the largest only"):
        check_mesh(v, f, "scatter.obj")
    # one edge shared by many fins: a triangle soup, no inside
    fins = np.array([[0, 1, 2 + i] for i in range(40)])
    ang = np.linspace(0, np.pi, 40)
    pts = np.vstack([[0, 0, 0], [0, 1, 0], np.c_[np.cos(ang), np.full(40, 0.5), np.sin(ang)]])
    with pytest.raises(RigFileError, match="soup.obj: .*holes?|soup.obj: .*shared by more"):
        check_mesh(pts, fins, "soup.obj")


def test_point_cloud_and_glb_mesh(tmp_path):
    cloud = tmp_path / "cloud.obj"
    cloud.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    with pytest.raises(RigFileError, match=r"cloud.obj: expected a surface mesh .* point cloud"):
        read_mesh(cloud)
    with pytest.raises(RigFileError, match="pts: expected a surface mesh"):
        check_mesh(np.eye(3), np.zeros((0, 3), int), "pts")
    if not CESIUM.is_file():
        pytest.skip(f"{CESIUM} is absent (shared test data)")
    v, f = read_mesh(CESIUM)
    # skinned at rest: standing +Y up (the file binds it Z up)
    assert np.ptp(v[:, 1]) > 1.4 and v[:, 1].min() > -0.01
    c = check_mesh(v, f, CESIUM)
    assert c.holes == [] and len(c.part_shares) == 1   # split at UV seams, closed once welded
