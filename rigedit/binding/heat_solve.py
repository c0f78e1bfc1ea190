"""The heat system and its solve: ``(L + M H) w = M H p`` for every joint at once, on the
parts of the mesh where some vertex sees a bone (:mod:`.heat`).

One sparse Cholesky factorisation (CHOLMOD when scikit-sparse is installed, SciPy's SuperLU
otherwise) and one block right-hand side, a column per joint.
"""
from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

try:  # CHOLMOD: measured faster than SuperLU (see benchmarks/bench_weights.py)
    from sksparse.cholmod import cholesky as _cholmod
except ImportError:  # pragma: no cover - machines without scikit-sparse
    _cholmod = None

__all__ = ["heat_system", "factor_solve"]


def heat_system(L, mass, H, ties, pairs_v, pairs_j, solvable, n_joints):
    """The heat equilibrium's matrix and right-hand sides on the ``solvable`` vertices.

    Parameters
    ----------
    L : (W, W) sparse
        The Laplacian (stiffness).
    mass : (W,) float64
        The lumped mass (0 for a vertex in no triangle).
    H : (W,) float64
        ``ties c / d^2`` (0 where no bone is seen).
    ties : (W,) int
        How many nearest visible joints share each vertex.
    pairs_v, pairs_j : (P,) int
        Each (vertex, visible nearest joint column) pair.
    solvable : (W,) bool
    n_joints : int
        The columns of ``pairs_j``.

    Returns
    -------
    A : (S, S) CSR float64
        ``L + M H`` restricted to the S solvable vertices (in order).
    B : (S, n_joints) float64
        ``M H p``: each vertex's ``M H / ties`` on its nearest visible joints' columns.
    """
    n = len(H)
    keep = np.flatnonzero(solvable)
    # A vertex in no triangle has no mass; give it a little so that H reaches it.
    m = np.where(mass > 0, mass, max(float(np.median(mass[mass > 0])) if (mass > 0).any()
                                      else 1.0, 1e-300) * 1e-3)
    mh = m * H
    A = (L + sp.diags(mh)).tocsr()[keep][:, keep]
    pos = np.full(n, -1)
    pos[keep] = np.arange(len(keep))
    inside = solvable[pairs_v]
    B = np.zeros((len(keep), n_joints))
    np.add.at(B, (pos[pairs_v[inside]], pairs_j[inside]),
              mh[pairs_v[inside]] / ties[pairs_v[inside]])
    return A, B


def factor_solve(A, B, solver="auto"):
    """Solve the SPD system ``A X = B`` for a block of right-hand sides; timings."""
    if solver not in ("auto", "cholmod", "splu"):
        raise ValueError(f"expected solver 'auto', 'cholmod' or 'splu', got {solver!r}")
    if solver == "cholmod" and _cholmod is None:
        raise ValueError("solver 'cholmod' needs scikit-sparse, which is not installed")
    t0 = time.perf_counter()
    if _cholmod is not None and solver != "splu":
        factor = _cholmod(A.tocsc())
        t1 = time.perf_counter()
        X = factor(B)
    else:
        from scipy.sparse.linalg import splu
        factor = splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                      options={"SymmetricMode": True})
        t1 = time.perf_counter()
        X = factor.solve(B)
    return np.asarray(X), t1 - t0, time.perf_counter() - t1
