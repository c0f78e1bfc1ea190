"""Weight brush maths (rigedit.binding.weight_paint): only vertices under the brush change, rows
sum to 1, locked joints keep their weights, smooth evens out, the mirror dab."""
import numpy as np
import pytest

from rigedit.binding.weight_paint import (brush_vertices, falloff, joint_column, mirror_vertices,
                                        paint, paint_mirrored, vertex_adjacency)


def grid(n=11):
    """A flat n x n grid of vertices in x-y (x from -1 to 1), triangulated."""
    xs = np.linspace(-1, 1, n)
    x, y = np.meshgrid(xs, xs, indexing="ij")
    verts = np.column_stack([x.ravel(), y.ravel(), np.zeros(n * n)])
    faces = []
    for i in range(n - 1):
        for j in range(n - 1):
            a, b, c, d = i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1, i * n + j + 1
            faces += [(a, b, c), (a, c, d)]
    return verts, np.array(faces)


def weights_by_x(verts, k=3):
    """Joints 0 (left, x<0), 1 (right) and 2 (everywhere a little): 3 influences a vertex."""
    left = np.clip(0.5 - verts[:, 0], 0.05, 0.9)
    idx = np.tile([0, 1, 2], (len(verts), 1)).astype(np.int32)
    w = np.column_stack([left, 0.9 - left, np.full(len(verts), 0.1)])
    w /= w.sum(axis=1, keepdims=True)
    return idx[:, :k], w[:, :k]


def dense(idx, w, j=4):
    out = np.zeros((len(idx), j))
    np.add.at(out, (np.repeat(np.arange(len(idx)), idx.shape[1]), idx.ravel()), w.ravel())
    return out


def test_falloff_is_one_at_centre_zero_at_rim():
    assert falloff([0.0, 1.0, 2.0], 1.0).tolist() == [1.0, 0.0, 0.0]
    f = falloff(np.linspace(0, 1, 20), 1.0)
    assert np.all(np.diff(f) < 0)


@pytest.mark.parametrize("mode", ["add", "subtract", "set", "smooth"])
def test_only_vertices_within_the_radius_change_and_rows_sum_to_one(mode):
    verts, faces = grid()
    idx, w = weights_by_x(verts)
    centre, radius = np.array([0.3, 0.1, 0.0]), 0.45
    vs, f = brush_vertices(verts, centre, radius)
    assert 0 < len(vs) < len(verts)
    ni, nw = paint(idx, w, 4, 1, vs, f, mode, 0.8, value=0.0 if mode == "set" else 1.0,
                   adjacency=vertex_adjacency(faces, len(verts)))
    before, after = dense(idx, w), dense(ni, nw)
    changed = np.flatnonzero(np.abs(after - before).max(axis=1) > 1e-12)
    inside = np.linalg.norm(verts - centre, axis=1) < radius
    assert len(changed) > 0 and inside[changed].all()
    np.testing.assert_allclose(nw.sum(axis=1), 1.0, atol=1e-12)
    assert (nw >= 0).all() and ni.shape == idx.shape


def test_add_raises_and_subtract_lowers_the_painted_joint():
    verts, _ = grid()
    idx, w = weights_by_x(verts)
    vs, f = brush_vertices(verts, [0.0, 0.0, 0.0], 0.5)
    col = joint_column(idx, w, 0)[vs]
    up = joint_column(*paint(idx, w, 4, 0, vs, f, "add", 0.5), 0)[vs]
    down = joint_column(*paint(idx, w, 4, 0, vs, f, "subtract", 0.5), 0)[vs]
    assert (up > col).all() and (down < col).all()


def test_locked_joints_keep_their_weights():
    verts, _ = grid()
    idx, w = weights_by_x(verts)
    vs, f = brush_vertices(verts, [0.0, 0.0, 0.0], 0.8)
    for mode in ("add", "subtract", "set"):
        ni, nw = paint(idx, w, 4, 1, vs, f, mode, 1.0, value=1.0, locked=[2])
        np.testing.assert_allclose(joint_column(ni, nw, 2), joint_column(idx, w, 2), atol=1e-12)
        np.testing.assert_allclose(nw.sum(axis=1), 1.0, atol=1e-12)
    # full strength set to 1 with joint 2 locked: joint 1 takes everything but joint 2's share
    ni, nw = paint(idx, w, 4, 1, vs, np.ones(len(vs)), "set", 1.0, value=1.0, locked=[2])
    np.testing.assert_allclose(joint_column(ni, nw, 1)[vs], 1.0 - joint_column(idx, w, 2)[vs])
    with pytest.raises(ValueError, match="locked"):
        paint(idx, w, 4, 2, vs, f, "add", 0.5, locked=[2])


def test_smooth_reduces_variation():
    verts, faces = grid()
    idx, w = weights_by_x(verts)
    col = joint_column(idx, w, 0)
    col_sharp = np.where(verts[:, 0] < 0, 0.85, 0.05)  # a hard seam at x = 0
    w = np.column_stack([col_sharp, 0.9 - col_sharp, np.full(len(verts), 0.1)])
    adj = vertex_adjacency(faces, len(verts))
    vs, f = brush_vertices(verts, [0.0, 0.0, 0.0], 0.6)
    ni, nw = paint(idx, w, 4, 0, vs, f, "smooth", 1.0, adjacency=adj)

    def roughness(c):  # summed squared difference along the edges near the brush
        a, b = adj.nonzero()
        near = np.isin(a, vs)
        return float(((c[a] - c[b])[near] ** 2).sum())

    assert roughness(joint_column(ni, nw, 0)) < 0.7 * roughness(col_sharp)
    np.testing.assert_allclose(nw.sum(axis=1), 1.0, atol=1e-12)
    assert not np.allclose(col, col_sharp)


def test_at_most_k_influences_and_tiny_ones_dropped():
    verts, _ = grid()
    idx, w = weights_by_x(verts, k=3)
    idx2, w2 = idx[:, :2].copy(), w[:, :2] / w[:, :2].sum(axis=1, keepdims=True)  # K = 2
    vs, f = brush_vertices(verts, [0.0, 0.0, 0.0], 0.5)
    ni, nw = paint(idx2, w2, 4, 3, vs, f, "add", 0.3)  # a third joint joins: one must go
    assert ni.shape == (len(verts), 2)
    after = dense(ni, nw)
    assert ((after > 0).sum(axis=1) <= 2).all() and (after[vs, 3] > 0).any()
    np.testing.assert_allclose(nw.sum(axis=1), 1.0, atol=1e-12)
    # subtract at full strength from joint 1: it goes, not left at a tiny value
    ni, nw = paint(idx, w, 4, 1, vs, np.ones(len(vs)), "subtract", 1.0)
    assert (joint_column(ni, nw, 1)[vs] == 0).all()


def test_subtract_from_a_sole_influence_goes_to_the_fallback_joint():
    idx = np.array([[1, 0]], dtype=np.int32)
    w = np.array([[1.0, 0.0]])
    ni, nw = paint(idx, w, 3, 1, [0], [1.0], "subtract", 0.25, fallback=0)
    np.testing.assert_allclose(dense(ni, nw, 3)[0], [0.25, 0.75, 0.0])
    ni, nw = paint(idx, w, 3, 1, [0], [1.0], "subtract", 0.25)  # no fallback: stays whole
    np.testing.assert_allclose(dense(ni, nw, 3)[0], [0.0, 1.0, 0.0])


def test_mirror_vertices_of_a_symmetric_grid():
    verts, _ = grid()
    m = mirror_vertices(verts, axis=0)
    np.testing.assert_allclose(verts[m, 0], -verts[:, 0])
    np.testing.assert_allclose(verts[m, 1], verts[:, 1])
    lopsided = verts.copy()
    lopsided[verts[:, 0] > 0.5, 1] += 0.5  # the right side's far part moved: no mirrors there
    m = mirror_vertices(lopsided, axis=0)
    assert (m[lopsided[:, 0] < -0.5] == -1).all() and (m[np.abs(verts[:, 0]) < 0.3] >= 0).all()


def test_mirrored_dab_paints_the_mirror_joint_on_the_other_side():
    verts, _ = grid()
    n = len(verts)
    # joints 0 (left), 1 (right) mirror each other; 2 central
    idx = np.tile([0, 1, 2], (n, 1)).astype(np.int32)
    w = np.tile([0.3, 0.3, 0.4], (n, 1))
    mv = mirror_vertices(verts, 0)
    mj = np.array([1, 0, 2])
    vs, f = brush_vertices(verts, [-0.6, 0.2, 0.0], 0.3)
    ni, nw = paint_mirrored(idx, w, 3, 0, vs, f, mv, mj, mode="add", strength=0.5)
    c0, c1 = joint_column(ni, nw, 0), joint_column(ni, nw, 1)
    np.testing.assert_allclose(c1[mv[vs]], c0[vs])  # the same change, mirrored
    changed = np.flatnonzero(np.abs(dense(ni, nw, 3) - dense(idx, w, 3)).max(axis=1) > 0)
    assert set(changed) == set(vs) | set(mv[vs])
    np.testing.assert_allclose(nw.sum(axis=1), 1.0, atol=1e-12)
    # a central joint across the middle: each vertex changes once, symmetric result
    vs, f = brush_vertices(verts, [0.0, 0.0, 0.0], 0.5)
    ni, nw = paint_mirrored(idx, w, 3, 2, vs, f, mv, mj, mode="add", strength=0.5)
    c2 = joint_column(ni, nw, 2)
    np.testing.assert_allclose(c2, c2[mv], atol=1e-12)
    single = joint_column(*paint(idx, w, 3, 2, vs, f, "add", 0.5), 2)
    np.testing.assert_allclose(c2, single, atol=1e-12)  # not applied twice
