"""Dual-quaternion skinning: no candy wrapper, rigid vertices as LBS, rest pose, antipodality,
scale; the compiled kernel and the numpy reference alike."""
import os

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from builders import chain_skeleton, cylinder
from rigedit.model import SkinBinding
from rigedit.model import skinning_kernels
from rigedit.model.dqs import dqs_skin, palette_dual_quaternions
from rigedit.rig import Rig

if os.environ.get(skinning_kernels.DISABLE_ENV):
    BACKENDS = ["numpy"]
else:
    BACKENDS = ["numpy", "numba"]


def affine(rotation=None, translation=(0, 0, 0), linear=None):
    m = np.eye(4)
    m[:3, :3] = rotation.as_matrix() if rotation is not None else np.eye(3)
    if linear is not None:
        m[:3, :3] = m[:3, :3] @ linear
    m[:3, 3] = translation
    return m


def twisted_cylinder_rig():
    """A cylinder (radius 0.3, y from 0 to 3) on two joints (y = 0 and y = 1.5); the weight
    of the upper joint ramps from 0 at y = 0.75 to 1 at y = 2.25."""
    sk = chain_skeleton(2, length=1.5)
    v, f = cylinder(radius=0.3, height=3.0)
    w1 = np.clip((v[:, 1] - 0.75) / 1.5, 0.0, 1.0)
    idx = np.tile([0, 1], (len(v), 1))
    return Rig(sk, v, f, indices=idx, weights=np.c_[1.0 - w1, w1], name="twist")


@pytest.mark.parametrize("backend", BACKENDS)
def test_twist_180_keeps_the_mid_section_with_dqs_and_collapses_it_with_lbs(backend):
    rig = twisted_cylinder_rig()
    pose = rig.rest_pose()
    pose.set_euler("j1", [0, 180, 0], degrees=True)  # about the bone's own axis (+Y)
    mid = (np.abs(rig.vertices[:, 1] - 1.5) < 1e-9) & (np.hypot(*rig.vertices[:, [0, 2]].T) > 0.1)
    assert mid.sum() == 24  # one full ring of the cylinder
    radius = {}
    for method in ("lbs", "dqs"):
        out = rig.binding.skin(
            np.matmul(rig.joint_matrices(pose), rig.skeleton.inverse_bind_matrices),
            method=method, backend=backend).copy()
        radius[method] = np.hypot(out[mid, 0], out[mid, 2])
        assert np.allclose(out[mid, 1], 1.5, atol=1e-5)
    assert radius["dqs"].min() >= 0.9 * 0.3
    assert radius["lbs"].max() <= 0.05 * 0.3  # LBS: (I + R_180) / 2 flattens the ring


@pytest.mark.parametrize("backend", BACKENDS)
def test_rig_skin_dqs_of_the_rest_pose_is_the_rest_mesh(cyl_rig, backend):
    out = cyl_rig.binding.skin(np.matmul(cyl_rig.joint_matrices(cyl_rig.rest_pose()),
                                         cyl_rig.skeleton.inverse_bind_matrices),
                               method="dqs", backend=backend)
    assert np.allclose(out, cyl_rig.vertices, atol=1e-5)
    assert np.allclose(cyl_rig.skin(cyl_rig.rest_pose(), method="dqs"), cyl_rig.vertices,
                       atol=1e-5)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("with_scale", [False, True])
def test_single_influence_vertices_move_as_with_lbs(backend, with_scale):
    rng = np.random.default_rng(3 + with_scale)
    j = 6
    rots = Rotation.random(j, random_state=5)
    palette = np.stack([
        affine(rots[i], rng.normal(size=3),
               # non-uniform scale and shear in bind space, and one mirroring joint
               (np.diag(rng.uniform(0.5, 2.0, 3)) + 0.2 * rng.normal(size=(3, 3))) *
               (np.array([[-1], [1], [1]]) if i == 0 else 1) if with_scale else None)
        for i in range(j)])
    rest = rng.normal(size=(300, 3))
    idx = np.c_[rng.integers(0, j, 300), rng.integers(0, j, 300)]
    w = np.c_[np.ones(300), np.zeros(300)]  # the second influence carries no weight
    binding = SkinBinding(rest, idx, w, j)
    lbs = binding.skin(palette, method="lbs", backend=backend).copy()
    dqs = binding.skin(palette, method="dqs", backend=backend).copy()
    expected = np.einsum("vij,vj->vi", palette[idx[:, 0], :3, :], np.c_[rest, np.ones(300)])
    assert np.allclose(lbs, expected, atol=2e-5 * np.abs(expected).max())
    assert np.allclose(dqs, expected, atol=2e-5 * np.abs(expected).max())


def run_dqs(backend, rest, indices, weights, dq):
    """Skin with given dual quaternions (their signs as given) on one backend."""
    if backend == "numpy":
        return dqs_skin(rest, indices, weights, dq)
    kernels = skinning_kernels.load()
    out = np.empty((len(rest), 3), np.float32)
    f32 = lambda a: np.ascontiguousarray(a, dtype=np.float32)  # noqa: E731
    pad = (0, 4 - np.shape(indices)[1])  # the kernel takes influences in groups of four
    none = np.empty((0, 3), np.float32)  # no normals
    kernels.dqs(f32(rest), none, np.pad(np.asarray(indices, np.int32), ((0, 0), pad)),
                np.pad(f32(weights), ((0, 0), pad)), f32(dq),
                skinning_kernels.hemisphere_signs(f32(dq), np.empty((len(dq),) * 2, np.float32)),
                np.zeros((len(dq), 9), np.float32), False, out, none)
    return out


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("flip", [(1, 1), (1, -1), (-1, 1), (-1, -1)])
def test_blend_takes_the_short_way_whatever_the_quaternion_signs(backend, flip):
    # Joint 0 turned +100 degrees about Y, joint 1 -100. The short way between them passes
    # through 180 degrees, so a vertex weighted half and half turns by 180, and one weighted
    # 0.6 / 0.4 lands between -100 and -180; a blend of q0 and a q1 of the other sign would
    # go the long way, through 0. q and -q are the same rotation: the signs must not matter.
    palette = np.stack([affine(Rotation.from_euler("y", a, degrees=True)) for a in (100, -100)])
    dq, _, _ = palette_dual_quaternions(palette)
    dq = dq * np.array(flip, dtype=float)[:, None]
    rest = np.array([[0.4, 0.2, 0.1], [0.0, 1.0, 0.5]])
    out = run_dqs(backend, rest, [[0, 1], [1, 0]], [[0.5, 0.5], [0.6, 0.4]], dq)
    assert np.allclose(out[0], [-0.4, 0.2, -0.1], atol=1e-5)
    assert np.isclose(out[1, 1], 1.0, atol=1e-6)
    assert np.isclose(np.hypot(out[1, 0], out[1, 2]), 0.5, atol=1e-5)
    # the turn of rest point (0, 0, 0.5) about +Y: +Z goes to +X for positive angles
    angle = np.degrees(np.arctan2(out[1, 0], out[1, 2]))
    assert -180 < angle < -140  # nlerp of 0.6 / 0.4 over the 160-degree short way: -161


def test_palette_split_recovers_rigid_motion_and_scale():
    rng = np.random.default_rng(7)
    rot = Rotation.random(4, random_state=1)
    linear = np.diag([1.0, 2.0, 0.5])
    palette = np.stack([affine(rot[i], rng.normal(size=3), linear if i else None)
                        for i in range(4)])
    dq, scale, has_scale = palette_dual_quaternions(palette)
    assert has_scale
    assert np.allclose(np.linalg.norm(dq[:, :4], axis=1), 1.0)
    assert np.allclose(scale[0], np.eye(3)) and np.allclose(scale[1], linear)
    assert np.allclose(np.abs(np.einsum("ji,ji->j", dq[:, :4], rot.as_quat())), 1.0)
    # a rigid palette has no scale and the translation comes back from the dual part
    _, _, rigid = palette_dual_quaternions(palette[:1])
    assert not rigid
    out = dqs_skin(np.zeros((1, 3)), [[0]], [[1.0]], dq[:1])
    assert np.allclose(out[0], palette[0, :3, 3])


def test_matrix_to_quaternion_matches_scipy_up_to_sign():
    from rigedit.model.dqs import matrix_to_quaternion

    rots = Rotation.concatenate([Rotation.random(500, random_state=2),
                                 Rotation.from_rotvec(np.pi * np.eye(3)),  # half turns
                                 Rotation.identity()])
    q = matrix_to_quaternion(rots.as_matrix())
    assert np.allclose(np.abs(np.einsum("ji,ji->j", q, rots.as_quat())), 1.0, atol=1e-12)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("k", [0, 4])
def test_a_binding_without_vertices_skins_to_nothing(backend, k):
    binding = SkinBinding(np.zeros((0, 3)), np.zeros((0, k), int), np.zeros((0, k)), 3)
    palette = np.tile(np.eye(4), (3, 1, 1))
    for method in ("lbs", "dqs"):
        assert binding.skin(palette, method=method, backend=backend).shape == (0, 3)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("with_scale", [False, True])
def test_normals_of_single_influence_vertices_turn_with_their_joint(backend, with_scale):
    """One influence: the normal is the joint's 3x3 times the rest normal, renormalised (its
    rotation alone when rigid), as LBS's normals."""
    rng = np.random.default_rng(11 + with_scale)
    j, v = 5, 203   # not a whole number of the kernel's 16-vertex blocks
    linear = [np.diag(rng.uniform(0.5, 2.0, 3)) + 0.2 * rng.normal(size=(3, 3)) if with_scale
              else None for _ in range(j)]
    palette = np.stack([affine(Rotation.random(random_state=i), rng.normal(size=3), linear[i])
                        for i in range(j)])
    rest_normals = rng.normal(size=(v, 3))
    rest_normals /= np.linalg.norm(rest_normals, axis=1, keepdims=True)
    idx = rng.integers(0, j, (v, 1))
    binding = SkinBinding(rng.normal(size=(v, 3)), idx, np.ones((v, 1)), j)
    binding.bind_normals(rest_normals)
    _, normals = binding.skin_with_normals(palette, backend=backend, method="dqs")
    expected = np.einsum("vij,vj->vi", palette[idx[:, 0], :3, :3], rest_normals)
    expected /= np.linalg.norm(expected, axis=1, keepdims=True)
    assert np.abs(normals - expected).max() < 2e-5
    lbs = binding.skin_with_normals(palette, backend=backend, method="lbs")[1]
    assert np.abs(lbs - expected).max() < 2e-5


@pytest.mark.parametrize("backend", BACKENDS)
def test_normals_skinned_with_dqs_follow_recomputed_normals_in_a_bend(cyl_rig, backend):
    from rigedit.model import skinning_matrices
    from rigedit.model.skinning import vertex_normals

    binding = cyl_rig.binding
    binding.bind_normals(vertex_normals(cyl_rig.vertices, cyl_rig.faces))
    pose = cyl_rig.rest_pose()
    pose.set_euler("j1", [0, 0, 60], degrees=True)
    pose.set_translation("j0", [0.5, 0.0, -1.0])
    pal = skinning_matrices(cyl_rig.skeleton, cyl_rig.joint_matrices(pose))
    verts, normals = (a.copy() for a in binding.skin_with_normals(pal, backend=backend,
                                                                  method="dqs"))
    assert np.allclose(verts, binding.skin(pal, method="dqs", backend="numpy"), atol=1e-5)
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-5)
    cos = (normals * vertex_normals(verts, cyl_rig.faces)).sum(axis=1)
    angle = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    # Measured with heat's c = 4 (a tighter blend at the joint, as artists weight, so a
    # sharper crease than c = 1 gave: mean 3.1, p95 9.4, max 13.5): mean 1.7 degrees, 95th
    # percentile 8.7, max 21.4, against LBS's 2.0, 10.2 and 32.9 on the same weights.
    assert angle.mean() < 2.5 and np.percentile(angle, 95) < 10.0 and angle.max() < 25.0
    lbs_v, lbs_n = (a.copy() for a in binding.skin_with_normals(pal, backend=backend,
                                                                method="lbs"))
    lbs_cos = (lbs_n * vertex_normals(lbs_v, cyl_rig.faces)).sum(axis=1)
    lbs_angle = np.degrees(np.arccos(np.clip(lbs_cos, -1.0, 1.0)))
    assert angle.max() < lbs_angle.max() and angle.mean() < lbs_angle.mean()
    with pytest.raises(ValueError, match="skinning method"):
        binding.skin_with_normals(pal, backend=backend, method="linear")
