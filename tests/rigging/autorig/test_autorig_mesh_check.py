"""rigging.mesh_check: what an auto-rigged mesh may be, and the one error otherwise."""
from __future__ import annotations

from testpaths import REPO
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import ConvexHull

import rigedit
from rigedit.errors import RigFileError
from rigedit.io.mesh import save_obj
from rigedit.rigging.autorig.mesh_check import MAX_HOLE, check_mesh, read_mesh

CESIUM = REPO.parent / "shared" / "data" / "khronos-gltf" / \
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


def test_no_back_is_one_error_naming_the_file(body):
    v, f = body
    keep = v[f].mean(axis=1)[:, 2] > 0.0        # the front half only: a shell, no volume
    with pytest.raises(RigFileError) as err:
        check_mesh(v, f[keep], "front.obj")
    msg = str(err.value)
    assert msg.startswith("front.obj: no volume to place a skeleton in: only ")
    assert "an open shell or sheet (open mesh: 1 hole, the largest " in msg


def test_big_hole_goes_through_the_proxy(body):
    v, f = body
    keep = v[f].mean(axis=1)[:, 1] > 0.9        # the upper body, open at the waist
    c = check_mesh(v, f[keep], "bust.obj")
    assert c.proxy is not None and c.proxy_reason.startswith("open mesh: 1 hole, the largest")
    pv, pf = c.embedding_mesh()
    assert pv is c.proxy.vertices and pf is c.proxy.faces
    # closed: every edge of the proxy is shared by an even number of its triangles
    _, count = np.unique(np.sort(np.concatenate([pf[:, [0, 1]], pf[:, [1, 2]],
                                                 pf[:, [2, 0]]]), axis=1), axis=0,
                         return_counts=True)
    assert np.all(count % 2 == 0)
    assert c.lines()[-1].startswith("proxy: open mesh: 1 hole, the largest ")
    assert "embedded in a watertight proxy of " in c.lines()[-1]


def test_closed_mesh_keeps_the_fast_path(body):
    c = check_mesh(*body, "human.obj")
    assert c.proxy is None and c.proxy_reason == ""
    pv, pf = c.embedding_mesh()
    assert len(pv) == len(c.vertices) and len(pf) == len(c.faces)


def test_small_parts_ride_along_outside_the_embedding(body):
    v, f = body
    eye, eye_f = _sphere(60, centre=(0.03, 1.65, 0.1), radius=0.01)
    verts = np.vstack([v, eye])
    faces = np.vstack([f, eye_f + len(v)])
    c = check_mesh(verts, faces, "parts.obj")
    assert len(c.part_shares) == 2 and c.proxy is None
    # the eye is left out of the embedding
    assert c.body.sum() == len(f)
    assert "2 parts" in c.lines()[3] and "1 small ones" in c.lines()[3]


def test_big_parts_go_through_the_proxy(body):
    v, f = body
    big, big_f = _sphere(300, centre=(0.0, 1.0, -0.3), radius=0.15, seed=1)  # a backpack
    c = check_mesh(np.vstack([v, big]), np.vstack([f, big_f + len(v)]), "pack.obj")
    assert c.proxy is not None
    assert "2 separate parts over 1% of the area each" in c.proxy_reason
    assert "all in the proxy" in c.lines()[3]


def test_scatter_of_pieces_and_soup_are_errors():
    pieces = [_sphere(20, centre=(3.0 * i, 0, 0), radius=1.0, seed=i) for i in range(12)]
    v = np.vstack([p[0] for p in pieces])
    f = np.vstack([p[1] + 20 * i for i, p in enumerate(pieces)])
    with pytest.raises(RigFileError, match=r"scatter.obj: the volume falls into 12 separate "
                                           r"pieces, the largest only"):
        check_mesh(v, f, "scatter.obj")
    # fins round one edge: a non-manifold soup of sheets, no inside (a dense fan of fins
    # would enclose one, as hair cards do)
    fins = np.array([[0, 1, 2 + i] for i in range(4)])
    ang = np.linspace(0, np.pi, 4)
    pts = np.vstack([[0, 0, 0], [0, 1, 0], np.c_[np.cos(ang), np.full(4, 0.5), np.sin(ang)]])
    with pytest.raises(RigFileError, match="soup.obj: no volume to place a skeleton in: .*"
                                           "shared by more than two triangles"):
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
