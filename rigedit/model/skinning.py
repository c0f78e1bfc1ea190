"""Skinning with a binding precomputed once: linear blend (LBS) and dual quaternions (DQS).

Two paths compute the same thing: compiled numba kernels (:mod:`.skinning_kernels`, one pass
over the vertices, used once compiled in the background) and numpy (the reference and the
fallback: for LBS one sparse product, for DQS :func:`.dqs.dqs_skin`).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from . import skinning_kernels
from .dqs import dqs_skin, palette_dual_quaternions
from .fast_paths import csr_times_dense_into
from .morph import MorphedRest

__all__ = ["SkinBinding", "linear_blend_skin", "top_k_influences", "dense_weights", "METHODS",
           "BACKENDS", "vertex_normals"]

#: A skinning matrix whose 3x3 ``A`` has ``AᵀA`` this close to the identity is rigid for DQS.
DQS_RIGID_TOL = 1e-6
#: Skinning methods: linear blend, dual quaternion.
METHODS = ("lbs", "dqs")
#: Where a frame is computed: None picks the compiled kernels once they are loaded, numpy
#: until then; "numba" waits for the kernels (raises when they cannot load); "numpy".
BACKENDS = (None, "numba", "numpy")


def top_k_influences(weights, k):
    """Keep the ``k`` largest influences per vertex and renormalise.

    Parameters
    ----------
    weights : (V, J) float array or sparse matrix
    k : int

    Returns
    -------
    indices : (V, k) int32
    values : (V, k) float64, rows sum to 1 (a vertex with no weight gets joint 0)
    """
    if sp.issparse(weights):
        weights = weights.toarray()
    weights = np.asarray(weights, dtype=np.float64)
    v, j = weights.shape
    k = min(k, j)
    if k < j:
        idx = np.argpartition(-weights, k - 1, axis=1)[:, :k]
    else:
        idx = np.broadcast_to(np.arange(j), (v, j)).copy()
    vals = np.take_along_axis(weights, idx, axis=1)
    order = np.argsort(-vals, axis=1)
    idx = np.take_along_axis(idx, order, axis=1)
    vals = np.clip(np.take_along_axis(vals, order, axis=1), 0.0, None)
    total = vals.sum(axis=1, keepdims=True)
    empty = total[:, 0] <= 0
    vals[empty] = 0.0
    vals[empty, 0] = 1.0
    total[empty] = 1.0
    return idx.astype(np.int32), vals / total


def vertex_normals(vertices, faces):
    """Area-weighted unit vertex normals of a triangle mesh (zero for unused vertices).

    Parameters
    ----------
    vertices : (V, 3) float
    faces : (F, 3) int

    Returns
    -------
    normals : (V, 3) float64
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    # the cross product's length is twice the triangle's area: larger faces weigh more
    face_n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n = np.zeros_like(v)
    for corner in range(3):
        np.add.at(n, f[:, corner], face_n)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0)


def dense_weights(indices, values, num_joints):
    """(V, K) influences -> dense (V, J) float64 weights (for colouring and debugging)."""
    v = len(indices)
    out = np.zeros((v, num_joints))
    np.add.at(out, (np.repeat(np.arange(v), indices.shape[1]), indices.ravel()), values.ravel())
    return out


class SkinBinding:
    """A mesh bound to a skeleton: rest vertices and top-K influences, ready to skin.

    Parameters
    ----------
    rest_vertices : (V, 3) float
        Vertex positions in the bind pose.
    indices : (V, K) int
        Joint index of each influence.
    weights : (V, K) float
        Influence weights; rows are renormalised to sum to 1.
    num_joints : int
    morphs : rigedit.model.morph.MorphTargets, optional
        Morph targets of the rest vertices: every pass skins ``rest + sum w * delta`` for the
        weights of :meth:`set_morph_weights` (glTF's order: morph, then skin); the rest
        normals get the normal deltas, renormalised by the pass. With all weights 0 a frame
        reads the plain rest arrays, at no cost.

    Notes
    -----
    The compiled kernels read the (V, K) influences as float32 weights and int32 indices and
    blend each vertex's K skinning matrices in registers. The numpy path holds the weights as
    a sparse (V, J) float32 matrix ``W`` (``matrix``): a frame computes ``B = W · P`` where
    ``P`` is (J, 12), each joint's skinning matrix's top three rows, which gives every vertex
    its blended 3x4 matrix, then applies it to the rest vertex. Every per-frame buffer is
    allocated here, once.
    """

    def __init__(self, rest_vertices, indices, weights, num_joints, morphs=None):
        rest = np.asarray(rest_vertices, dtype=np.float64)
        if rest.ndim != 2 or rest.shape[1] != 3:
            raise ValueError(f"expected rest vertices of shape (V, 3), got {rest.shape}")
        indices = np.asarray(indices)
        weights = np.asarray(weights, dtype=np.float64)
        if indices.shape != weights.shape or indices.shape[0] != rest.shape[0]:
            raise ValueError(f"expected indices and weights of shape ({rest.shape[0]}, K), got "
                             f"{indices.shape} and {weights.shape}")
        if indices.size and (indices.min() < 0 or indices.max() >= num_joints):
            raise ValueError(f"expected joint indices in [0, {num_joints - 1}], got "
                             f"{indices.min()}..{indices.max()}")
        total = weights.sum(axis=1, keepdims=True)
        if np.any(total <= 0):
            raise ValueError(f"vertex {int(np.argmax(total[:, 0] <= 0))} has no weight")
        self.num_joints = int(num_joints)
        self.rest_vertices = rest
        self.indices = indices.astype(np.int32)
        self.weights = weights / total
        v, k = indices.shape
        rows = np.repeat(np.arange(v), k)
        w = sp.csr_matrix((self.weights.ravel().astype(np.float32),
                           (rows, self.indices.ravel())), shape=(v, self.num_joints))
        w.sum_duplicates()
        w.eliminate_zeros()
        w.sort_indices()
        # Row-major: one pass over the output. A CSC product makes one pass per joint, which
        # measured 6x slower at 1M vertices once the (V, 12) output no longer fits in cache.
        self.matrix = w
        self._rest32 = rest.astype(np.float32)
        self._palette = np.empty((self.num_joints, 12), dtype=np.float32)
        self._blend = np.empty((v, 12), dtype=np.float32)
        self._out = np.empty((v, 3), dtype=np.float32)
        self._tmp = np.empty((v, 3), dtype=np.float32)
        # The kernels' inputs: C-contiguous float32 / int32 (the exact compiled signature),
        # each vertex's influences sorted by decreasing weight and padded with zero weights to
        # a multiple of 4 (the kernels blend four at a time and skip a group starting at zero),
        # and the palette as rows of 16 floats (each 4x4 transposed, see skinning_simd).
        order = np.argsort(-self.weights, axis=1, kind="stable")
        k4 = max(4, -(-k // 4) * 4)
        self._indices32 = np.zeros((v, k4), dtype=np.int32)
        self._weights32 = np.zeros((v, k4), dtype=np.float32)
        self._indices32[:, :k] = np.take_along_axis(self.indices, order, 1)
        self._weights32[:, :k] = np.take_along_axis(self.weights, order, 1)
        self._palette16 = np.empty((self.num_joints, 16), dtype=np.float32)
        self._dq = np.empty((self.num_joints, 8), dtype=np.float32)
        self._scale = np.empty((self.num_joints, 9), dtype=np.float32)
        # the DQS kernel's (J, J) hemisphere table, made at the first DQS frame: a rig of
        # 100,000 joints skinned with LBS never allocates 10^10 entries
        self._signs = None
        self._rest_normals32 = None  # set by bind_normals
        #: The morph targets (None without) and the rest arrays with their current weights.
        self.morphs = morphs
        self._morphed = None if morphs is None else MorphedRest(morphs, self._rest32)
        if self._morphed is not None:
            self._morphed.set_weights(None)          # the targets' default weights
        self._out_normals = None
        self._no_normals = np.empty((0, 3), dtype=np.float32)  # the DQS kernel without normals
        #: Threads of the compiled kernels: None picks one for small meshes, all for big ones
        #: (see ``skinning_kernels.PARALLEL_MIN_VERTICES``).
        self.threads = None

    @property
    def num_vertices(self):
        return self.rest_vertices.shape[0]

    def dense(self):
        """(V, J) float64 weights."""
        return dense_weights(self.indices, self.weights, self.num_joints)

    # ------------------------------------------------------------------ morphs
    @property
    def morph_weights(self):
        """(M,) float64: the weights every pass applies (empty without morph targets)."""
        return np.zeros(0) if self._morphed is None else self._morphed.weights.copy()

    def set_morph_weights(self, weights):
        """Set the morph weights the following passes apply: None (the targets' defaults),
        (M,) numbers or ``{name: weight}`` (others keep their default). Only the rows the old
        and new active targets move are rewritten. Returns True when the rest changed; a
        binding without targets ignores weights (as a target's name that it lacks)."""
        return False if self._morphed is None else self._morphed.set_weights(weights)

    @property
    def _rest_now(self):
        """(V, 3) float32: the rest points with the current morphs (the rest itself without)."""
        return self._rest32 if self._morphed is None else self._morphed.points

    @property
    def _normals_now(self):
        """(V, 3) float32 or None: the rest normals with the current morphs."""
        return self._rest_normals32 if self._morphed is None else self._morphed.normals

    def _kernels(self, backend):
        """The compiled kernels to use for ``backend``, or None for the numpy path."""
        if backend not in BACKENDS:
            raise ValueError(f"expected a skinning backend in {BACKENDS}, got {backend!r}")
        if backend == "numpy":
            return None
        if backend == "numba":
            kernels = skinning_kernels.load()
            if kernels is None:
                raise RuntimeError(f"the compiled skinning kernels are not available "
                                   f"({skinning_kernels.error()})")
            return kernels
        if self.num_vertices >= skinning_kernels.AUTO_LOAD_MIN_VERTICES:
            skinning_kernels.start_loading()
        return skinning_kernels.ready()

    def _output(self, out):
        if out is None:
            return self._out
        if out.shape != self._out.shape:
            raise ValueError(f"expected out of shape {self._out.shape}, got {out.shape}")
        return out

    def skin(self, palette, out=None, method="lbs", backend=None):
        """Skinned vertex positions for a palette of skinning matrices.

        Parameters
        ----------
        palette : (J, 4, 4) float
            Skinning matrices ``M_j · inverse_bind_j``.
        out : (V, 3) array, optional
            Where to write; by default an internal float32 buffer that the next call
            overwrites (copy it to keep it).
        method : {"lbs", "dqs"}
            Linear blend or dual-quaternion skinning (:meth:`skin_dqs`).
        backend : {None, "numba", "numpy"}
            See ``BACKENDS``; None uses the compiled kernels once they are loaded.

        Returns
        -------
        vertices : (V, 3) float32 (or ``out``)
        """
        if method == "dqs":
            return self.skin_dqs(palette, out=out, backend=backend)
        if method != "lbs":
            raise ValueError(f"expected a skinning method in {METHODS}, got {method!r}")
        kernels = self._kernels(backend)
        res = self._output(out)
        if kernels is not None and res.dtype == np.float32 and res.flags.c_contiguous:
            self._palette16.reshape(-1, 4, 4)[:] = np.asarray(palette).transpose(0, 2, 1)
            kernels.run("lbs", len(res), self.threads, self._rest_now, self._indices32,
                        self._weights32, self._palette16, res)
            return res
        self._palette[:] = np.asarray(palette)[:, :3, :].reshape(-1, 12)
        # in place into the frame's buffer where SciPy allows it (see fast_paths)
        b = csr_times_dense_into(self.matrix, self._palette, self._blend).reshape(-1, 3, 4)
        # res = b[:, :, :3] @ rest + b[:, :, 3], written column by column into the buffers to
        # avoid the (V, 3, 3) temporaries an einsum would make.
        r = self._rest_now
        tmp = self._tmp
        np.multiply(b[:, :, 0], r[:, 0:1], out=res)
        np.multiply(b[:, :, 1], r[:, 1:2], out=tmp)
        res += tmp
        np.multiply(b[:, :, 2], r[:, 2:3], out=tmp)
        res += tmp
        res += b[:, :, 3]
        return res

    def bind_normals(self, rest_normals):
        """Keep unit rest normals, (V, 3), for :meth:`skin_with_normals` (for example
        ``vertex_normals(rest_vertices, faces)``)."""
        n = np.asarray(rest_normals, dtype=np.float64)
        if n.shape != self.rest_vertices.shape:
            raise ValueError(f"expected rest normals of shape {self.rest_vertices.shape}, got "
                             f"{n.shape}")
        self._rest_normals32 = np.ascontiguousarray(n, dtype=np.float32)
        self._out_normals = np.empty_like(self._rest_normals32)
        if self._morphed is not None:
            self._morphed.bind_normals(self._rest_normals32)

    def skin_with_normals(self, palette, backend=None, method="lbs"):
        """Vertex positions and normals in one pass. LBS: each vertex's blended 3x3 applied to
        its rest normal, renormalised (exact for rotations and uniform scale, as shading
        needs; not the inverse transpose under non-uniform scale). DQS: the rest normal turned
        by the vertex's blended rotation (after its blended scale/shear, when the palette has
        any), renormalised. Needs :meth:`bind_normals`.

        Parameters
        ----------
        palette : (J, 4, 4) float
        backend : {None, "numba", "numpy"}
        method : {"lbs", "dqs"}

        Returns
        -------
        vertices, normals : (V, 3) float32 each
            Internal buffers that the next call overwrites.
        """
        if self._rest_normals32 is None:
            raise ValueError("no rest normals: call bind_normals first")
        if method not in METHODS:
            raise ValueError(f"expected a skinning method in {METHODS}, got {method!r}")
        kernels = self._kernels(backend)
        res, nrm = self._out, self._out_normals
        normals = self._normals_now
        if method == "dqs":
            if kernels is not None:
                self._run_dqs(kernels, palette, normals, res, nrm)
            else:
                res[:], nrm[:] = self._dqs_numpy(palette, normals)
            return res, nrm
        if kernels is not None:
            self._palette16.reshape(-1, 4, 4)[:] = np.asarray(palette).transpose(0, 2, 1)
            kernels.run("lbs_normals", len(res), self.threads, self._rest_now,
                        normals, self._indices32, self._weights32,
                        self._palette16, res, nrm)
            return res, nrm
        self.skin(palette, backend="numpy")  # fills self._blend with each vertex's 3x4
        b = self._blend.reshape(-1, 3, 4)
        rn = normals
        np.einsum("vij,vj->vi", b[:, :, :3], rn, out=nrm)
        length = np.linalg.norm(nrm, axis=1, keepdims=True)
        np.divide(nrm, length, out=nrm, where=length > 0)
        return res, nrm

    def skin_dqs(self, palette, out=None, backend=None):
        """Dual-quaternion skinned vertex positions (see :mod:`rigedit.model.dqs` for the
        antipodality and scale handling).

        Parameters
        ----------
        palette : (J, 4, 4) float
            Skinning matrices ``M_j · inverse_bind_j``.
        out : (V, 3) array, optional
            As in :meth:`skin`.
        backend : {None, "numba", "numpy"}

        Returns
        -------
        vertices : (V, 3) float32 (or ``out``)
        """
        kernels = self._kernels(backend)
        res = self._output(out)
        if kernels is not None and res.dtype == np.float32 and res.flags.c_contiguous:
            self._run_dqs(kernels, palette, self._no_normals, res, self._no_normals)
            return res
        res[:] = self._dqs_numpy(palette)
        return res

    def _dqs_numpy(self, palette, rest_normals=None):
        """The numpy reference of DQS (:func:`~rigedit.model.dqs.dqs_skin`): (V, 3) float64
        positions, and normals too when ``rest_normals`` (V, 3) is given."""
        dq, scale, has_scale = palette_dual_quaternions(palette, DQS_RIGID_TOL)
        rest = self._rest_now
        # the float64 rest as bound unless morphs are active (then their float32 sum)
        rest = self.rest_vertices if rest is self._rest32 else rest.astype(np.float64)
        return dqs_skin(rest, self.indices, self.weights, dq,
                        scale if has_scale else None, rest_normals=rest_normals)

    def _run_dqs(self, kernels, palette, rest_normals, out, out_normals):
        """The compiled DQS kernel: positions into ``out``, normals too unless
        ``out_normals`` has no rows."""
        palette = np.ascontiguousarray(palette, dtype=np.float64)
        if palette.shape != (self.num_joints, 4, 4):  # the kernel writes J rows of _dq
            raise ValueError(f"expected a palette of shape ({self.num_joints}, 4, 4), got "
                             f"{palette.shape}")
        has_scale = not kernels.rigid_dual_quaternions(palette, DQS_RIGID_TOL, self._dq)
        if has_scale:
            dq, scale, has_scale = palette_dual_quaternions(palette, DQS_RIGID_TOL)
            self._dq[:] = dq
            self._scale[:] = scale.reshape(-1, 9)
        if self._signs is None:
            self._signs = np.empty((self.num_joints, self.num_joints), dtype=np.float32)
        skinning_kernels.hemisphere_signs(self._dq, self._signs)
        kernels.run("dqs", len(out), self.threads, self._rest_now, rest_normals,
                    self._indices32, self._weights32, self._dq, self._signs, self._scale,
                    has_scale, out, out_normals)


def linear_blend_skin(binding, palette, out=None):
    """Functional form of :meth:`SkinBinding.skin`."""
    return binding.skin(palette, out=out)
