"""The private fast paths of rigedit.model.fast_paths give the numbers of their public
fallbacks (so a SciPy without the private kernel changes only the speed)."""
import numpy as np
import pytest
import scipy.sparse as sp

from rigedit.model import SkinBinding, fast_paths
from rigedit.model.skinning import top_k_influences


def random_csr(v, j, k, seed):
    rng = np.random.default_rng(seed)
    idx, w = top_k_influences(rng.random((v, j)) ** 4, k)
    m = sp.csr_matrix((w.ravel().astype(np.float32), (np.repeat(np.arange(v), k), idx.ravel())),
                      shape=(v, j))
    m.sort_indices()
    return m, rng.normal(size=(j, 12)).astype(np.float32)


@pytest.mark.skipif(not fast_paths.PRIVATE_CSR_MATVECS, reason="SciPy without csr_matvecs")
@pytest.mark.parametrize("v, j, k", [(1, 1, 1), (257, 7, 3), (5000, 40, 4)])
def test_the_private_and_the_public_sparse_product_agree(v, j, k):
    m, dense = random_csr(v, j, k, seed=v)
    fast = fast_paths.csr_times_dense_into(m, dense, np.full((v, 12), np.nan, np.float32),
                                           private=True)
    public = fast_paths.csr_times_dense_into(m, dense, np.full((v, 12), np.nan, np.float32),
                                             private=False)
    assert np.array_equal(fast, public)
    assert np.allclose(public, m.toarray() @ dense, atol=1e-5)


def test_the_numpy_skinning_path_is_the_same_with_the_public_product(monkeypatch):
    rng = np.random.default_rng(3)
    v, j = 2000, 9
    idx, w = top_k_influences(rng.random((v, j)) ** 4, 4)
    binding = SkinBinding(rng.normal(size=(v, 3)), idx, w, j)
    palette = np.tile(np.eye(4), (j, 1, 1))
    palette[:, :3, :] += 0.1 * rng.normal(size=(j, 3, 4))
    first = binding.skin(palette, backend="numpy").copy()
    monkeypatch.setattr(fast_paths, "PRIVATE_CSR_MATVECS", False)
    assert np.array_equal(binding.skin(palette, backend="numpy"), first)


def test_asking_for_a_missing_private_kernel_says_so(monkeypatch):
    monkeypatch.setattr(fast_paths, "_csr_matvecs", None)
    m, dense = random_csr(10, 3, 2, seed=1)
    with pytest.raises(RuntimeError, match="csr_matvecs"):
        fast_paths.csr_times_dense_into(m, dense, np.empty((10, 12), np.float32), private=True)
