"""The compiled skinning kernels agree with the numpy reference, and the numpy path takes over
when the kernels are disabled."""
import os
import subprocess
import sys

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rigedit.model import SkinBinding, skinning_kernels
from rigedit.model.skinning import top_k_influences

pytestmark = pytest.mark.skipif(bool(os.environ.get(skinning_kernels.DISABLE_ENV)),
                                reason="compiled kernels disabled by RIGEDIT_NO_NUMBA")


def random_binding(v, j, k, seed):
    rng = np.random.default_rng(seed)
    idx, w = top_k_influences(rng.random((v, j)) ** 6, k)
    return SkinBinding(rng.normal(size=(v, 3)) * 2.0, idx, w, j)


def random_palette(j, seed, scale=True):
    rng = np.random.default_rng(seed)
    pal = np.tile(np.eye(4), (j, 1, 1))
    pal[:, :3, :3] = Rotation.random(j, random_state=seed).as_matrix()
    if scale:
        pal[:, :3, :3] = pal[:, :3, :3] @ (np.eye(3) * rng.uniform(0.5, 1.5, (j, 1, 3))
                                           + 0.1 * rng.normal(size=(j, 3, 3)))
    pal[:, :3, 3] = rng.normal(size=(j, 3))
    return pal


def test_kernels_load():
    assert skinning_kernels.load() is not None, skinning_kernels.error()


@pytest.mark.parametrize("k", [1, 4, 8])
@pytest.mark.parametrize("method", ["lbs", "dqs"])
@pytest.mark.parametrize("scale", [False, True])
def test_compiled_and_numpy_paths_agree_to_float32_precision(k, method, scale):
    binding = random_binding(4000, 30, k, seed=k)
    for trial in range(3):
        pal = random_palette(30, seed=10 * k + trial, scale=scale)
        ref = binding.skin(pal, method=method, backend="numpy").copy()
        got = binding.skin(pal, method=method, backend="numba").copy()
        assert got.dtype == np.float32
        # float32 blends of a few terms of size ~5: a few units in the last place
        assert np.abs(got - ref).max() <= 4e-6 * max(1.0, np.abs(ref).max())


def test_compiled_path_rejects_other_types_instead_of_compiling():
    binding = random_binding(100, 5, 4, seed=1)
    kernels = skinning_kernels.load()
    with pytest.raises(TypeError):
        kernels.lbs(binding._rest32.astype(np.float64), binding._indices32, binding._weights32,
                    binding._palette, np.empty((100, 3), np.float32))


def test_out_of_another_dtype_goes_through_numpy():
    binding = random_binding(500, 8, 4, seed=2)
    pal = random_palette(8, seed=3)
    out64 = np.empty((500, 3))
    binding.skin(pal, out=out64, backend="numba")
    assert np.allclose(out64, binding.skin(pal, backend="numpy"), atol=1e-5)


def test_no_numba_environment_variable_forces_the_numpy_path():
    code = ("import sys, numpy as np\n"
            "from rigedit.model import SkinBinding, skinning_kernels as k\n"
            "b = SkinBinding(np.eye(3), [[0], [1], [1]], [[1.0], [1.0], [1.0]], 2)\n"
            "p = np.tile(np.eye(4), (2, 1, 1)); p[1, :3, 3] = [1, 2, 3]\n"
            "out = b.skin(p, method='dqs')\n"
            "print(k.load() is None, 'numba' in sys.modules, k.error())\n"
            "print(out.tolist())\n")
    env = dict(os.environ, RIGEDIT_NO_NUMBA="1")
    proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    first, second = proc.stdout.strip().splitlines()
    assert first == "True False disabled by RIGEDIT_NO_NUMBA"
    assert np.allclose(eval(second), [[1, 0, 0], [1, 3, 3], [1, 2, 4]])


def skinned_and_recomputed_normals(rig, binding, backend):
    from rigedit.model import skinning_matrices
    from rigedit.model.skinning import vertex_normals

    binding.bind_normals(vertex_normals(rig.vertices, rig.faces))
    pose = rig.rest_pose()
    pose.set_euler("j1", [0, 0, 60], degrees=True)
    pose.set_translation("j0", [0.5, 0.0, -1.0])
    pal = skinning_matrices(rig.skeleton, rig.joint_matrices(pose))
    verts, normals = (a.copy() for a in binding.skin_with_normals(pal, backend=backend))
    assert np.allclose(verts, binding.skin(pal, backend="numpy"), atol=1e-5)
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-5)
    cos = (normals * vertex_normals(verts, rig.faces)).sum(axis=1)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_normals_skinned_in_the_same_pass_match_recomputed_normals(cyl_rig, backend):
    # Smooth (inverse-distance) weights, a 60-degree bend: the blended 3x3 is not the
    # deformation's Jacobian, so normals in the bend differ from the recomputed ones;
    # measured mean 3.9 degrees, 95th percentile 15.7, max 29.1.
    angle = skinned_and_recomputed_normals(cyl_rig, cyl_rig.binding, backend)
    assert angle.mean() < 5.0 and np.percentile(angle, 95) < 20.0 and angle.max() < 35.0
    # Carried rigidly (every vertex on one joint), the normals are exact.
    n = len(cyl_rig.vertices)
    cyl_rig.bind(np.ones((n, 1), dtype=int), np.ones((n, 1)))
    assert skinned_and_recomputed_normals(cyl_rig, cyl_rig.binding, backend).max() < 0.05


def test_normals_need_rest_normals_of_the_right_shape():
    binding = random_binding(50, 4, 2, seed=4)
    with pytest.raises(ValueError, match="bind_normals"):
        binding.skin_with_normals(random_palette(4, seed=1))
    with pytest.raises(ValueError, match="rest normals"):
        binding.bind_normals(np.zeros((49, 3)))


def test_compiled_rigid_dual_quaternions_match_numpy_and_refuse_scale():
    from rigedit.model.dqs import palette_dual_quaternions

    kernels = skinning_kernels.load()
    pal = random_palette(50, seed=9, scale=False)
    pal[0, :3, :3] = np.diag([1.0, -1.0, -1.0])  # a half turn: the trace is not the largest
    dq = np.empty((50, 8), np.float32)
    assert kernels.rigid_dual_quaternions(pal, 1e-6, dq)
    ref, _, has_scale = palette_dual_quaternions(pal)
    assert not has_scale
    sign = np.sign(np.einsum("ji,ji->j", dq[:, :4], ref[:, :4]))[:, None]
    assert np.allclose(dq * sign, ref, atol=1e-6)
    assert not kernels.rigid_dual_quaternions(random_palette(50, seed=9), 1e-6, dq)
    mirrored = pal.copy()
    mirrored[3, :3, 0] *= -1
    assert not kernels.rigid_dual_quaternions(mirrored, 1e-6, dq)


def test_a_big_binding_loads_the_kernels_in_the_background_and_a_small_one_does_not():
    code = ("import numpy as np\n"
            "from rigedit.model import SkinBinding, skinning_kernels as k\n"
            "p = np.tile(np.eye(4), (2, 1, 1))\n"
            "small = SkinBinding(np.zeros((10, 3)), np.zeros((10, 1), int), np.ones((10, 1)), 2)\n"
            "small.skin(p)\n"
            "print(k._state['thread'] is None, k.ready() is None)\n"
            "n = k.AUTO_LOAD_MIN_VERTICES\n"
            "big = SkinBinding(np.random.default_rng(0).normal(size=(n, 3)),\n"
            "                  np.zeros((n, 1), int), np.ones((n, 1)), 2)\n"
            "first = big.skin(p).copy()  # numpy: the kernels are still loading\n"
            "k._state['thread'].join(300)\n"
            "print(k.ready() is not None, np.allclose(big.skin(p), first, atol=1e-6))\n")
    env = {k: v for k, v in os.environ.items() if k != skinning_kernels.DISABLE_ENV}
    proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, timeout=400)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["True", "True", "True", "True"]


@pytest.mark.parametrize("method", ["lbs", "dqs"])
def test_a_palette_of_the_wrong_size_is_refused(method):
    binding = random_binding(50, 4, 2, seed=5)
    with pytest.raises(ValueError):
        binding.skin(random_palette(6, seed=1), method=method, backend="numba")


def test_vector_kernel_refuses_a_palette_it_would_read_past():
    binding = random_binding(100, 5, 4, seed=1)
    kernels = skinning_kernels.load()
    with pytest.raises(ValueError, match="16 floats"):
        kernels.lbs(binding._rest32, binding._indices32, binding._weights32,
                    np.zeros((5, 12), np.float32), np.empty((100, 3), np.float32))


@pytest.mark.parametrize("v", [1, 15, 16, 17, 1023, 1024 + 16 + 5, 3 * 1024 + 40])
@pytest.mark.parametrize("scale", [False, True])
def test_dqs_kernel_blocks_and_their_remainders_agree_with_numpy(v, scale):
    """The DQS kernel transforms 16 vertices at a time in tasks of DQS_TASK vertices; counts
    around those sizes take the one-vertex path for the last few, and every vertex must be
    written (the outputs start as NaN), positions alone or with normals."""
    assert skinning_kernels.DQS_TASK == 1024
    binding = random_binding(v, 12, 8, seed=v)
    pal = random_palette(12, seed=v, scale=scale)
    ref = binding.skin(pal, method="dqs", backend="numpy").copy()
    rest_normals = np.random.default_rng(v).normal(size=(v, 3))
    rest_normals /= np.linalg.norm(rest_normals, axis=1, keepdims=True)
    binding.bind_normals(rest_normals)
    ref_normals = binding.skin_with_normals(pal, method="dqs", backend="numpy")[1].copy()
    for threads in (1, 2):
        binding.threads = threads
        out = np.full((v, 3), np.nan, np.float32)
        binding.skin(pal, method="dqs", out=out, backend="numba")
        assert np.abs(out - ref).max() <= 4e-6 * max(1.0, np.abs(ref).max())
        binding._out[:] = binding._out_normals[:] = np.nan
        verts, normals = binding.skin_with_normals(pal, method="dqs", backend="numba")
        assert np.abs(verts - ref).max() <= 4e-6 * max(1.0, np.abs(ref).max())
        assert np.abs(normals - ref_normals).max() <= 4e-6


def test_the_kernel_sources_name_these_vector_blocks():
    """numba's disk cache of a kernel follows the kernel's own file only: the kernels' files
    name the skinning_simd.py they inline, so editing it means editing them (new caches)."""
    from rigedit.model import dqs_kernels, lbs_kernels

    digest = skinning_kernels.simd_sha256()
    assert lbs_kernels.SIMD_SHA256 == dqs_kernels.SIMD_SHA256 == digest, (
        f"skinning_simd.py changed: set SIMD_SHA256 = {digest!r} in lbs_kernels.py and "
        "dqs_kernels.py")
    assert skinning_kernels.cache_is_current()


def test_vector_blocks_other_than_the_kernels_name_compile_without_the_disk_cache(
        monkeypatch):
    from rigedit.model import lbs_kernels

    monkeypatch.setattr(lbs_kernels, "SIMD_SHA256", "the hash of other intrinsics")
    with pytest.warns(RuntimeWarning, match="without numba's disk cache"):
        assert not skinning_kernels.cache_is_current()


def test_building_the_kernels_sets_no_module_names():
    """The kernels' sources import numba and the vector blocks themselves: building a
    Kernels object rebinds no module's globals (it once filled in prange and the blends)."""
    import numba

    from rigedit.model import dqs_kernels, lbs_kernels

    modules = (skinning_kernels, lbs_kernels, dqs_kernels)
    before = [dict(vars(m)) for m in modules]
    kernels = skinning_kernels.Kernels(numba)
    assert [dict(vars(m)) for m in modules] == before
    assert kernels.lbs.py_func is lbs_kernels.lbs_py and lbs_kernels.prange is numba.prange
