"""The one place rigedit names another library's private API, each with a public fallback.

Rule (issue 18): rigedit uses public APIs only, except where a private one is the only way to
a measured speed. Each such use lives here, is looked up once at import (``None`` when the
library moved or dropped it) and has a public fallback that gives the same numbers; the tests
run both paths (``tests/model/test_fast_paths.py``).

- :func:`csr_times_dense_into`: ``scipy.sparse._sparsetools.csr_matvecs``, the kernel behind
  ``csr_matrix @ dense``, writing into a buffer the caller keeps. The public product
  allocates its (V, 12) result every frame and is copied into the buffer: measured 25-35%
  slower on the numpy skinning path's sparse product (scipy 1.17, float32, 4 influences of 40
  joints, best CPU time: 0.12 vs 0.13 ms at 10k vertices, 1.2 vs 1.6 ms at 100k, 22 vs 30 ms
  at 1M), with bit-identical results.
"""
from __future__ import annotations

import numpy as np

__all__ = ["csr_times_dense_into", "PRIVATE_CSR_MATVECS"]

try:
    from scipy.sparse._sparsetools import csr_matvecs as _csr_matvecs
except ImportError:  # pragma: no cover - SciPy moved it: the public product below
    _csr_matvecs = None

#: True when SciPy's private in-place product was found at import (else the public path).
PRIVATE_CSR_MATVECS = _csr_matvecs is not None


def csr_times_dense_into(matrix, dense, out, private=None):
    """``out[:] = matrix @ dense`` without allocating the product when SciPy allows it.

    Parameters
    ----------
    matrix : (V, J) scipy.sparse.csr_matrix
        Canonical (sorted indices, no duplicates), of ``out``'s dtype.
    dense : (J, C) C-contiguous array of ``out``'s dtype
    out : (V, C) C-contiguous array
        Overwritten.
    private : bool, optional
        None (default) uses SciPy's private in-place kernel when it was found; False forces
        the public product (the fallback, for tests and comparisons); True requires the
        private kernel (``RuntimeError`` when it is missing).

    Returns
    -------
    out : (V, C) array
    """
    use_private = PRIVATE_CSR_MATVECS if private is None else bool(private)
    if use_private:
        if _csr_matvecs is None:
            raise RuntimeError("scipy.sparse._sparsetools.csr_matvecs is not available")
        out.fill(0)  # the kernel accumulates into its output
        _csr_matvecs(matrix.shape[0], matrix.shape[1], dense.shape[1], matrix.indptr,
                     matrix.indices, matrix.data, dense.ravel(), out.ravel())
    else:
        np.copyto(out, matrix @ dense)
    return out
