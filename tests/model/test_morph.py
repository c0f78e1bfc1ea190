"""Morph targets: the data, the displacement sum, and skinning with morphs."""
import numpy as np
import pytest

from rigedit.model.morph import MorphTargets


def _targets(V=6, seed=0):
    rng = np.random.default_rng(seed)
    deltas = np.zeros((2, V, 3), np.float32)
    deltas[0, :2] = rng.normal(size=(2, 3))                   # moves vertices 0 and 1
    deltas[1, 3:] = rng.normal(size=(V - 3, 3))
    return MorphTargets(("smile", "blink"), deltas)


def test_apply_is_the_weighted_sum_and_none_when_all_weights_are_zero():
    mt = _targets()
    assert mt.apply([0.0, 0.0]) is None and mt.apply(None) is None
    got = mt.apply([0.5, -2.0])
    want = 0.5 * mt.deltas[0] - 2.0 * mt.deltas[1]
    np.testing.assert_allclose(got, want, atol=1e-6)
    assert list(mt.moved_rows(0)) == [0, 1]
    np.testing.assert_allclose(mt.apply({"blink": 1.0}), mt.deltas[1])
    buf = np.full((6, 3), 9.0, np.float32)
    assert mt.apply({"smile": 1.0, "other": 3.0}, out=buf) is buf
    np.testing.assert_allclose(buf, mt.deltas[0])


def test_default_weights_apply_when_none_are_given():
    mt = MorphTargets(("a",), np.ones((1, 2, 3)), default_weights=[0.5])
    np.testing.assert_allclose(mt.apply(None), 0.5)
    np.testing.assert_allclose(mt.weights_array({}), [0.5])


@pytest.mark.parametrize("kwargs", [
    dict(names=("a", "a"), deltas=np.zeros((2, 3, 3))),
    dict(names=("a",), deltas=np.zeros((2, 3, 3))),
    dict(names=("a",), deltas=np.zeros((1, 3, 2))),
    dict(names=("a",), deltas=np.full((1, 3, 3), np.nan)),
    dict(names=("a",), deltas=np.zeros((1, 3, 3)), normal_deltas=np.zeros((1, 2, 3))),
    dict(names=("a",), deltas=np.zeros((1, 3, 3)), default_weights=[1.0, 2.0])])
def test_malformed_targets_are_refused(kwargs):
    with pytest.raises(ValueError):
        MorphTargets(**kwargs)


# ---------------------------------------------------------------------- skinning with morphs
from scipy.spatial.transform import Rotation  # noqa: E402

from builders import chain_skeleton, cylinder  # noqa: E402
from rigedit.model import Pose, SkinBinding, skinning_matrices, local_to_model  # noqa: E402
from rigedit.model import skinning_kernels  # noqa: E402
from rigedit.model.skinning import top_k_influences, vertex_normals  # noqa: E402
from rigedit.rig import Rig  # noqa: E402


def _morph_rig(seed=0):
    """The test cylinder on a 3-joint chain, 4 influences per vertex, and two targets: one
    moving the top rings outwards, one moving a strip of vertices along z (with normals)."""
    rng = np.random.default_rng(seed)
    sk = chain_skeleton(3)
    v, f = cylinder()
    idx, w = top_k_influences(rng.random((len(v), 3)) ** 4, 3)
    deltas = np.zeros((2, len(v), 3), np.float32)
    top = v[:, 1] > 2.0
    deltas[0, top] = 0.5 * v[top] * [1, 0, 1]
    strip = np.abs(v[:, 0]) < 0.1
    deltas[1, strip, 2] = rng.normal(size=strip.sum())
    ndeltas = np.zeros_like(deltas)
    ndeltas[1, strip] = rng.normal(size=(strip.sum(), 3)) * 0.3
    mt = MorphTargets(("bulge", "ridge"), deltas, ndeltas)
    return Rig(sk, v, f, idx, w, name="morphs", morphs=mt)


def _gltf_reference(rig, pose, weights):
    """glTF 2.0's vertex formula written out: the morphed rest point (rest + sum w_m * d_m,
    float64) times the weighted sum of the joint matrices (global transform of each joint
    node from its local TRS, times its inverse bind matrix)."""
    sk = rig.skeleton
    local = np.zeros((len(sk), 4, 4))
    for j in range(len(sk)):
        m = np.eye(4)
        m[:3, :3] = Rotation.from_quat(pose.rotation[j]).as_matrix() * pose.scale[j]
        m[:3, 3] = pose.translation[j]
        local[j] = m
    world = np.zeros_like(local)
    for j in range(len(sk)):              # parents come first in a Skeleton
        p = sk.parents[j]
        world[j] = local[j] if p < 0 else world[p] @ local[j]
    joint = world @ sk.inverse_bind_matrices
    rest = rig.vertices + sum(w * rig.morphs.deltas[m].astype(np.float64)
                              for m, w in enumerate(weights))
    idx, wts = rig.binding.indices, rig.binding.weights
    out = np.zeros_like(rest)
    for v in range(len(rest)):
        skin = sum(wts[v, k] * joint[idx[v, k]] for k in range(idx.shape[1]))
        out[v] = (skin @ np.r_[rest[v], 1.0])[:3]
    return out


def _pose(rig, seed):
    rng = np.random.default_rng(seed)
    n = len(rig.skeleton)
    pose = Pose(rig.skeleton)
    pose.rotation[:] = Rotation.random(n, random_state=seed).as_quat()
    pose.translation[:] += rng.normal(scale=0.2, size=(n, 3))
    pose.scale[:] = rng.uniform(0.8, 1.2, size=(n, 1))
    return pose


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("weights", [(0.7, 0.0), (0.3, -1.4), (0.0, 1.0)])
def test_rig_skin_with_morph_weights_matches_the_gltf_formula(backend, weights):
    rig = _morph_rig()
    if backend == "numba" and skinning_kernels.load() is None:
        pytest.skip("the compiled kernels do not load here")
    pose = _pose(rig, 3)
    want = _gltf_reference(rig, pose, weights)
    diag = np.linalg.norm(np.ptp(want, axis=0))
    palette = skinning_matrices(rig.skeleton, local_to_model(rig.skeleton, pose))
    rig.binding.set_morph_weights(weights)
    got_binding = rig.binding.skin(palette, backend=backend).astype(float)
    rig.binding.set_morph_weights(None)
    assert np.abs(got_binding - want).max() < 1e-5 * diag
    got = rig.skin(pose, morph_weights=dict(zip(rig.morphs.names, weights)))
    assert np.abs(got - want).max() < 1e-5 * diag
    # the morphs moved something, so the comparison could have failed
    assert np.abs(got - _gltf_reference(rig, pose, (0.0, 0.0))).max() > 1e-2 * diag


def test_zero_weights_skin_exactly_as_without_morphs_and_reuse_the_rest():
    rig = _morph_rig()
    plain = SkinBinding(rig.vertices, rig.binding.indices, rig.binding.weights, 3)
    palette = skinning_matrices(rig.skeleton, local_to_model(rig.skeleton, _pose(rig, 1)))
    for method in ("lbs", "dqs"):
        np.testing.assert_array_equal(rig.binding.skin(palette, method=method, backend="numpy"),
                                      plain.skin(palette, method=method, backend="numpy"))
    assert rig.binding._rest_now is rig.binding._rest32        # no copy, no time


def test_changing_weights_resets_the_rows_of_targets_no_longer_active():
    rig = _morph_rig()
    b = rig.binding
    palette = skinning_matrices(rig.skeleton, local_to_model(rig.skeleton, _pose(rig, 2)))
    b.set_morph_weights([1.0, 0.0])
    b.set_morph_weights([0.0, 0.5])          # bulge off, ridge on: bulge's rows go back
    want = SkinBinding(rig.vertices + 0.5 * rig.morphs.deltas[1], b.indices, b.weights, 3)
    np.testing.assert_allclose(b.skin(palette, backend="numpy"),
                               want.skin(palette, backend="numpy"), atol=1e-5)
    assert b.set_morph_weights([0.0, 0.5]) is False           # unchanged: nothing done
    b.set_morph_weights([0.0, 0.0])
    assert b._rest_now is b._rest32


@pytest.mark.parametrize("method", ["lbs", "dqs"])
def test_normals_get_their_deltas_and_are_renormalised(method):
    rig = _morph_rig()
    b = rig.binding
    rest_n = vertex_normals(rig.vertices, rig.faces)
    b.bind_normals(rest_n)
    b.set_morph_weights([0.0, 0.8])
    palette = skinning_matrices(rig.skeleton, local_to_model(rig.skeleton, _pose(rig, 4)))
    pts, nrm = b.skin_with_normals(palette, backend="numpy", method=method)
    moved_n = rest_n + 0.8 * rig.morphs.normal_deltas[1]
    want = SkinBinding(rig.vertices + 0.8 * rig.morphs.deltas[1], b.indices, b.weights, 3)
    want.bind_normals(moved_n / np.linalg.norm(moved_n, axis=1, keepdims=True))
    want_p, want_n = want.skin_with_normals(palette, backend="numpy", method=method)
    np.testing.assert_allclose(pts, want_p, atol=1e-5)
    np.testing.assert_allclose(nrm, want_n, atol=1e-4)
    np.testing.assert_allclose(np.linalg.norm(nrm, axis=1), 1.0, atol=1e-5)


def test_rig_skin_puts_the_editors_weights_back_and_rebinding_keeps_them():
    rig = _morph_rig()
    rig.binding.set_morph_weights([0.25, 0.0])
    rig.skin(rig.rest_pose(), morph_weights=[1.0, 1.0])
    np.testing.assert_array_equal(rig.binding.morph_weights, [0.25, 0.0])
    rig.bind(rig.binding.indices, rig.binding.weights)
    np.testing.assert_array_equal(rig.binding.morph_weights, [0.25, 0.0])
    assert rig.data().morphs is rig.morphs


def test_targets_of_another_vertex_count_are_refused():
    sk = chain_skeleton(3)
    v, f = cylinder()
    with pytest.raises(ValueError, match="vertices"):
        Rig(sk, v, f, np.zeros((len(v), 1), int), np.ones((len(v), 1)),
            morphs=MorphTargets(("a",), np.zeros((1, 5, 3))))


def test_a_sequence_of_weights_on_overlapping_targets_always_gives_rest_plus_the_sum():
    rng = np.random.default_rng(5)
    V = 50
    deltas = np.zeros((3, V, 3), np.float32)
    deltas[0, :30] = rng.normal(size=(30, 3))
    deltas[1, 20:] = rng.normal(size=(30, 3))            # overlaps target 0 on rows 20..29
    deltas[2] = rng.normal(size=(V, 3))                   # every row (the slice path)
    ndeltas = rng.normal(size=(3, V, 3)).astype(np.float32) * (deltas != 0)
    mt = MorphTargets(("a", "b", "c"), deltas, ndeltas)
    rest = rng.normal(size=(V, 3)).astype(np.float32)
    normals = rng.normal(size=(V, 3)).astype(np.float32)
    from rigedit.model.morph import MorphedRest
    mr = MorphedRest(mt, rest)
    for step in range(40):
        w = rng.choice([0.0, 0.0, 0.3, -1.2, 1.0], size=3)
        if step == 10:
            mr.bind_normals(normals)
        mr.set_weights(w)
        np.testing.assert_allclose(mr.points, rest + np.tensordot(w, deltas, 1), atol=1e-5)
        if step >= 10:
            np.testing.assert_allclose(mr.normals, normals + np.tensordot(w, ndeltas, 1),
                                       atol=1e-5)
    np.testing.assert_array_equal(rest, mr.rest)          # the rest itself never written


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("method", ["lbs", "dqs"])
def test_every_path_skins_the_morphed_rest_as_a_binding_of_it_would(backend, method):
    rig = _morph_rig(seed=2)
    if backend == "numba" and skinning_kernels.load() is None:
        pytest.skip("the compiled kernels do not load here")
    b = rig.binding
    rest_n = vertex_normals(rig.vertices, rig.faces)
    b.bind_normals(rest_n)
    b.set_morph_weights([0.6, -0.9])
    morphed = rig.vertices + 0.6 * rig.morphs.deltas[0] - 0.9 * rig.morphs.deltas[1]
    moved_n = rest_n - 0.9 * rig.morphs.normal_deltas[1]
    want = SkinBinding(morphed, b.indices, b.weights, 3)
    want.bind_normals(moved_n)
    palette = skinning_matrices(rig.skeleton, local_to_model(rig.skeleton, _pose(rig, 7)))
    np.testing.assert_allclose(b.skin(palette, method=method, backend=backend),
                               want.skin(palette, method=method, backend=backend), atol=2e-5)
    got_p, got_n = b.skin_with_normals(palette, backend=backend, method=method)
    want_p, want_n = want.skin_with_normals(palette, backend=backend, method=method)
    np.testing.assert_allclose(got_p, want_p, atol=2e-5)
    np.testing.assert_allclose(got_n, want_n, atol=1e-4)
