"""Bone-heat weights: smooth, complete, robust to bad meshes (rigedit.binding.heat)."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from builders import chain_skeleton, cylinder
from rigedit.model import Skeleton
from rigedit.binding.heat import HeatWeightsWarning, heat_weights
from rigedit.binding.laplacian import clean_faces, cotangent_laplacian, vertex_normals, weld
from rigedit.model.skinning import dense_weights
from rigedit.binding.tails import deforming_joints
from rigedit.binding.visibility import HAVE_NUMBA, SurfaceRays
from rigedit.binding.weights import compute_weights, idw_weights


def heat(v, sk, f, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HeatWeightsWarning)
        return heat_weights(v, sk, f, **kw)


def check_rows(idx, w, k):
    assert idx.shape == w.shape and idx.shape[1] <= k
    assert np.all(np.isfinite(w)) and np.all(w >= 0)
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-9)
    assert np.all(w.max(axis=1) > 0)


def ring_means(v, d, col):
    """Mean weight of joint ``col`` on each ring of the side wall (caps left out)."""
    side = np.isclose(np.hypot(v[:, 0], v[:, 2]), np.hypot(v[:, 0], v[:, 2]).max())
    v, d = v[side], d[side]
    ys = np.round(v[:, 1], 6)
    levels = np.unique(ys)
    return levels, np.array([d[ys == y, col].mean() for y in levels])


def open_cylinder(**kw):
    """The builders' cylinder without its caps (and without the two cap centres)."""
    v, f = cylinder(**kw)
    n = len(v) - 2
    f = f[np.all(f < n, axis=1)]
    return v[:n], f


# ---------------------------------------------------------------------------- smoothness
def test_two_bone_cylinder_is_smooth_and_monotone_across_the_joint():
    v, f = cylinder(height=2.0, rings=41)
    sk = chain_skeleton(2)                        # j0: y 0..1, j1: y 1..2 (tail)
    idx, w = heat(v, sk, f)
    check_rows(idx, w, 4)
    d = dense_weights(idx, w, 2)
    levels, upper = ring_means(v, d, 1)
    assert np.all(np.diff(upper) >= -1e-9)        # monotone along the axis
    assert upper[0] < 0.05 and upper[-1] > 0.95   # each end belongs to its own bone
    mid = np.argmin(np.abs(levels - 1.0))
    assert 0.3 < upper[mid] < 0.7                 # shared at the joint
    # smooth: no jump between neighbouring rings larger than a fifth of the range
    assert np.max(np.diff(upper)) < 0.2


def test_at_most_k_influences_and_tiny_ones_dropped():
    v, f = cylinder(height=4.0, rings=41)
    sk = chain_skeleton(4)
    idx, w = heat(v, sk, f, max_influences=2)
    check_rows(idx, w, 2)
    assert np.all((w == 0) | (w >= 0.01 - 1e-12))


def test_numpy_ray_tests_give_the_same_weights_as_the_compiled_ones():
    if not HAVE_NUMBA:
        pytest.skip("numba not installed: only the numpy path exists")
    v, f = cylinder(height=3.0)
    sk = chain_skeleton(3)
    a = heat(v, sk, f, use_numba=True)
    b = heat(v, sk, f, use_numba=False)
    np.testing.assert_allclose(dense_weights(*a, 3), dense_weights(*b, 3), atol=1e-9)


def test_superlu_and_cholmod_give_the_same_weights():
    from rigedit.binding import heat as heat_module
    if heat_module._cholmod is None:
        pytest.skip("scikit-sparse not installed: SuperLU is the only solver")
    v, f = cylinder(height=3.0)
    sk = chain_skeleton(3)
    a = heat(v, sk, f, solver="cholmod")
    b = heat(v, sk, f, solver="splu")
    np.testing.assert_allclose(dense_weights(*a, 3), dense_weights(*b, 3), atol=1e-9)


# ---------------------------------------------------------------------------- any mesh
def test_two_parts_every_vertex_weighted_and_the_far_part_reported():
    v, f = cylinder(height=3.0)
    far = v + [10.0, 0.21, 0.13]                 # off the planes of the near part's caps
    verts = np.vstack([v, far])
    faces = np.vstack([f, f + len(v)])
    with pytest.warns(HeatWeightsWarning, match="no bone can see"):
        res = heat_weights(verts, chain_skeleton(3), faces)
    idx, w = res
    check_rows(idx, w, 4)
    np.testing.assert_array_equal(res.fallback, np.arange(len(v), 2 * len(v)))
    # the near part is solved by heat, the far one by the nearest bones (idw's rule)
    assert res.fallback.min() == len(v)


def test_open_cylinder_works_and_matches_the_closed_one_in_the_middle():
    v, f = open_cylinder(height=2.0, rings=41)
    sk = chain_skeleton(2)
    res = heat(v, sk, f)
    check_rows(*res, 4)
    assert len(res.fallback) == 0
    _, upper = ring_means(v, dense_weights(*res, 2), 1)
    assert np.all(np.diff(upper) >= -1e-9) and upper[0] < 0.05 and upper[-1] > 0.95


def test_open_part_far_from_the_origin_is_oriented_by_its_own_centre():
    # a cup: the cylinder without its top cap (the top centre is the last vertex); about
    # the origin, 25 units below its rim, its signed volume would come out negative
    v, f = cylinder(height=2.0, rings=21)
    f = f[np.all(f < len(v) - 1, axis=1)]
    v = v[:-1]
    shift = np.array([40.0, 25.0, 30.0])
    sk = chain_skeleton(2)
    sk = Skeleton(sk.names, sk.parents, sk.rest_translation + [shift, [0] * 3],
                  tails=sk.tails + shift)
    res = heat(v + shift, sk, f)
    assert len(res.fallback) == 0
    normals = vertex_normals(v + shift, f)
    side = np.abs(v[:, 1] - 1.0) < 0.9
    radial = v * [1, 0, 1]
    assert np.all(np.einsum("ij,ij->i", normals[side], radial[side]) > 0)   # outward


def test_split_seam_duplicates_and_a_sliver_give_no_nan_and_agree_with_the_welded_mesh():
    v, f = cylinder(height=2.0, rings=21, segments=16)
    sk = chain_skeleton(2)
    base = dense_weights(*heat(v, sk, f), 2)
    # split the seam: column 0 of every ring duplicated, faces on one side re-pointed
    col0 = np.arange(21) * 16
    dup = np.arange(len(v), len(v) + len(col0))
    v2 = np.vstack([v, v[col0]])
    f2 = f.copy()
    remap = dict(zip(col0, dup))
    for r, face in enumerate(f2):
        if 15 in face % 16 and np.any(face % 16 == 0) and np.all(face < 21 * 16):
            f2[r] = [remap.get(x, x) for x in face]
    # a sliver: three nearly collinear new vertices on the surface, as a separate triangle
    p = v[5]
    sliver = np.array([p, p + [1e-3, 0, 0], p + [2e-3, 1e-12, 0]])
    v3 = np.vstack([v2, sliver])
    f3 = np.vstack([f2, [[len(v2), len(v2) + 1, len(v2) + 2]]])
    res = heat(v3, sk, f3)
    idx, w = res
    check_rows(idx, w, 4)
    d = dense_weights(idx, w, 2)
    np.testing.assert_allclose(d[dup], d[col0], atol=1e-9)   # duplicates weld together
    np.testing.assert_allclose(d[:len(v)], base, atol=1e-6)  # the seam is not a cut


def test_operator_is_positive_semidefinite_even_with_slivers_and_nonmanifold_edges():
    rng = np.random.default_rng(1)
    v = rng.normal(size=(30, 3))
    v[3] = v[1] + 1e-9 * (v[2] - v[1])                         # a near-zero-area triangle
    f = rng.integers(0, 30, size=(80, 3))
    f = np.vstack([f, [[1, 2, 3], [1, 2, 4], [1, 2, 5]]])      # edge 1-2 in three triangles
    f = clean_faces(f)
    L, mass = cotangent_laplacian(v, f)
    assert np.all(np.isfinite(L.data)) and np.all(mass >= 0)
    np.testing.assert_allclose(L.sum(axis=1), 0.0, atol=1e-9)
    assert np.linalg.eigvalsh(L.toarray()).min() > -1e-9


def test_weld_merges_only_coincident_points():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 0], [1, 1e-9, 0], [2, 0, 0.0]])
    rep, welded = weld(v, 1e-6)
    assert rep[0] == rep[2] and rep[1] == rep[3] and len(set(rep)) == 3
    np.testing.assert_allclose(welded[rep], v, atol=1e-6)


# ---------------------------------------------------------------------------- visibility
def u_shape(gap=0.1, radius=0.25, height=1.5, rings=60, segments=16):
    """A tube along a U (two arms joined at the bottom), arms along +Y at x = -/+ a."""
    a = radius + gap / 2
    t = np.linspace(0, 1, rings * 3)
    # centreline: down the left arm, round the bottom, up the right arm
    arc = np.pi * np.clip((t - 1 / 3) * 3, 0, 1)
    left, right = t < 1 / 3, t > 2 / 3
    x = np.where(left, -a, np.where(right, a, -a * np.cos(arc)))
    y = np.where(left, height * (1 - 3 * t), np.where(right, height * (3 * t - 2),
                                                       -a * np.sin(arc)))
    c = np.stack([x, y, np.zeros_like(x)], 1)
    tan = np.gradient(c, axis=0)
    tan /= np.linalg.norm(tan, axis=1, keepdims=True)
    n1 = np.cross(tan, [0, 0, 1.0])
    n1 /= np.linalg.norm(n1, axis=1, keepdims=True)
    ang = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    ring = np.cos(ang)[None, :, None] * n1[:, None] + np.sin(ang)[None, :, None] * [0, 0, 1.0]
    v = (c[:, None] + radius * ring).reshape(-1, 3)
    m = len(c)
    faces = []
    for r in range(m - 1):
        for s in range(segments):
            p, q = r * segments + s, r * segments + (s + 1) % segments
            faces += [(p, q, q + segments), (p, q + segments, p + segments)]
    ends = [len(v), len(v) + 1]
    v = np.vstack([v, c[0], c[-1]])
    for s in range(segments):
        faces.append((ends[0], (s + 1) % segments, s))
        faces.append((ends[1], (m - 1) * segments + s, (m - 1) * segments + (s + 1) % segments))
    return v, np.array(faces), a


def test_inner_side_of_a_u_does_not_take_the_other_arms_bone():
    v, f, a = u_shape()
    # Left arm's bone stops low, the right arm's runs the whole height: high on the left
    # arm's inner side, the right bone is nearer (across the gap) than the left one.
    names = ["base", "left", "right"]
    heads = np.array([[0, -0.3, 0], [-a, 0.0, 0], [a, 0.0, 0]])
    tails = np.array([[np.nan] * 3, [-a, 0.5, 0], [a, 1.5, 0]])
    sk = Skeleton(names, [-1, 0, 0], np.array([heads[0], heads[1] - heads[0],
                                               heads[2] - heads[0]]), tails=tails)
    inner = (np.abs(v[:, 0] - (-a + 0.25)) < 0.02) & (v[:, 1] > 1.2)
    assert inner.sum() >= 3
    d_left = np.linalg.norm(v[inner] - [-a, 0.5, 0], axis=1)
    d_right = np.abs(v[inner, 0] - a)
    assert np.all(d_right < d_left)             # the wrong bone is the nearest one
    d = dense_weights(*heat(v, sk, f), 3)
    assert np.all(d[inner, 1] > 0.9)            # but the vertex keeps its own arm
    di = dense_weights(*idw_weights(v, sk), 3)
    assert np.all(di[inner, 2] > 0.5)           # which distance alone gets wrong


def test_ray_tests_agree_between_compiled_and_numpy_and_on_a_known_case():
    v, f = cylinder(height=2.0, rings=11, segments=12)
    rays = SurfaceRays(v, f)
    # from the axis out through the wall: blocked; along the axis inside: free
    assert rays.blocked([[0, 1, 0]], [[1, 1, 0]])[0]
    assert not rays.blocked([[0, 0.5, 0]], [[0, 1.5, 0]])[0]
    t = rays.first_hit([[0, 1, 0]], [[0.6, 1, 0]])[0]
    assert 0.45 < t < 0.51                      # the wall is at radius 0.3 (a chord inside)
    rng = np.random.default_rng(0)
    o = rng.normal(size=(300, 3)) * [0.5, 1, 0.5] + [0, 1, 0]
    e = rng.normal(size=(300, 3)) * [0.5, 1, 0.5] + [0, 1, 0]
    skip = rng.integers(-1, len(v), 300)
    a = rays.first_hit(o, e, skip)
    b = SurfaceRays(v, f, use_numba=False).first_hit(o, e, skip)
    assert np.isfinite(a).sum() > 50
    np.testing.assert_allclose(a, b, atol=1e-12)


# ---------------------------------------------------------------------------- limit cases
def test_single_joint_takes_everything():
    v, f = cylinder()
    sk = Skeleton(["only"], [-1], [[0.0, 1.5, 0.0]])
    idx, w = heat(v, sk, f)
    assert np.all(idx[:, 0] == 0) and np.allclose(w[:, 0], 1.0)


def test_away_from_joints_heat_and_idw_pick_the_same_bone():
    v, f = cylinder(radius=0.1, height=4.0, rings=41)
    sk = chain_skeleton(4)
    dh = dense_weights(*heat(v, sk, f), 4)
    di = dense_weights(*idw_weights(v, sk), 4)
    frac = v[:, 1] % 1.0
    mid = (frac > 0.4) & (frac < 0.6) & (v[:, 1] < 3.9)
    np.testing.assert_array_equal(dh[mid].argmax(axis=1), di[mid].argmax(axis=1))
    assert np.all(dh[mid].max(axis=1) > 0.9)


def test_non_deforming_joints_take_no_weight():
    v, f = cylinder(height=3.0)
    sk = chain_skeleton(3)
    sk.deform[1] = False
    idx, w = heat(v, sk, f)
    assert not np.any((idx == 1) & (w > 0))


def test_root_carrier_below_the_mesh_and_zero_length_bones_do_not_deform():
    v, f = cylinder(height=2.0)
    v = v + [0, 1.0, 0]                              # the body from y=1 to y=3
    names = ["root", "hips", "helper", "chest"]
    # root at the origin (on the ground, outside the body); helper at hips' place
    local = [[0, 0, 0], [0, 1.2, 0], [0, 0, 0], [0, 0.9, 0]]
    sk = Skeleton(names, [-1, 0, 1, 2], local, tails=[[np.nan] * 3] * 3 + [[0, 2.9, 0]])
    deform = deforming_joints(sk, v, vertex_normals(v, f))
    np.testing.assert_array_equal(deform, [False, False, True, True])
    # hips' only bone (to helper) has zero length; the helper runs hips to chest
    idx, w = heat(v, sk, f)
    assert not np.any(np.isin(idx, [0, 1]) & (w > 0))


def test_leaf_without_tail_gets_one_inside_the_mesh():
    v, f = cylinder(height=3.0)
    sk = Skeleton(["a", "b", "c"], [-1, 0, 1], [[0, 0.0, 0], [0, 1, 0], [0, 1, 0]])
    res = heat(v, sk, f)
    tail = res.tails[2]
    assert np.all(np.isfinite(tail))
    assert 2.2 < tail[1] < 3.0 and np.hypot(tail[0], tail[2]) < 1e-6


# ---------------------------------------------------------------------------- bad input
def test_nan_coordinates_are_one_clear_error():
    v, f = cylinder()
    v[7, 1] = np.nan
    with pytest.raises(ValueError, match="finite.*vertex|NaN or inf"):
        compute_weights(v, chain_skeleton(3), "heat", faces=f)


def test_heat_without_faces_is_one_clear_error():
    v, _ = cylinder()
    for faces in (None, np.zeros((0, 3), int)):
        with pytest.raises(ValueError, match="faces"):
            compute_weights(v, chain_skeleton(3), "heat", faces=faces)


def test_no_deforming_joint_is_an_error():
    v, f = cylinder()
    sk = chain_skeleton(3)
    sk.deform[:] = False
    with pytest.raises(ValueError, match="deforming joint"):
        heat_weights(v, sk, f)


def test_face_index_out_of_range_is_an_error():
    v, f = cylinder()
    f[0, 0] = len(v)
    with pytest.raises(ValueError, match="face indices"):
        heat_weights(v, chain_skeleton(3), f)


def test_bones_outside_the_mesh_give_weights_and_a_warning():
    v, f = cylinder()
    sk = chain_skeleton(3)
    shift = [5.0, 0.21, 0.13]
    sk = Skeleton(sk.names, sk.parents, sk.rest_translation + [shift, [0] * 3, [0] * 3],
                  tails=sk.tails + shift)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = heat_weights(v, sk, f)
    said = " ".join(str(w.message) for w in caught if w.category is HeatWeightsWarning)
    assert "outside the mesh" in said and "no bone can see" in said
    check_rows(*res, 4)
    assert len(res.fallback) == len(v)          # no bone inside: nearest bones for all


def test_single_vertex_islands_are_weighted():
    v, f = cylinder(height=3.0)
    inside = [[0.0, 2.5, 0.0]]                   # a stray point inside the body
    outside = [[3.0, 1.5, 0.0]]                  # and one far outside
    verts = np.vstack([v, inside, outside])
    res = heat(verts, chain_skeleton(3), f)
    idx, w = res
    check_rows(idx, w, 4)
    assert idx[len(v), 0] == 2 and w[len(v), 0] > 0.99     # nearest visible bone: j2
    assert len(v) + 1 in res.fallback                      # sees its bone from outside


def test_progress_is_reported_and_a_raise_cancels():
    v, f = cylinder()
    seen = []
    heat(v, chain_skeleton(3), f, progress=seen.append)
    assert seen == sorted(seen) and seen[-1] == 1.0 and len(seen) >= 4

    class Stop(Exception):
        pass

    def cancel(frac):
        if frac > 0.3:
            raise Stop
    with pytest.raises(Stop):
        heat(v, chain_skeleton(3), f, progress=cancel)


# ---------------------------------------------------------------------------- wiring
def test_rig_defaults_to_heat_and_the_cli_prints_the_fallback_count(tmp_path, capsys):
    from rigedit.cli.main import main
    from rigedit.io import load_weights, save_rig_folder
    from rigedit.rig import Rig
    v, f = cylinder(height=3.0)
    verts = np.vstack([v, v + [10.0, 0.21, 0.13]])
    faces = np.vstack([f, f + len(v)])
    sk = chain_skeleton(3)
    rig = heat_rig = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HeatWeightsWarning)
        heat_rig = Rig(sk, verts, faces)
        rig = Rig(sk, verts, np.zeros((0, 3), int))            # a point cloud: idw
    assert heat_rig.weights_method == "heat" and rig.weights_method == "idw"
    expected = heat(verts, sk, faces)
    np.testing.assert_allclose(heat_rig.binding.weights, expected[1], atol=1e-6)
    save_rig_folder(tmp_path / "two", heat_rig)
    out = tmp_path / "w.npz"
    assert main(["weights", str(tmp_path / "two"), "-o", str(out)]) == 0
    captured = capsys.readouterr()
    assert "method heat" in captured.out and f"{len(v)} fallback vertices" in captured.out
    warned = [line for line in captured.err.splitlines() if "no bone can see" in line]
    assert len(warned) == 1 and warned[0].startswith(f"rigedit: warning: heat weights: {len(v)} ")
    idx, w = load_weights(out, sk, len(verts))
    np.testing.assert_array_equal(idx[:, 0], expected[0][:, 0])
