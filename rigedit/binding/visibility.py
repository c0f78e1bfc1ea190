"""Segment-against-surface tests for bone visibility: a BVH over the triangles, compiled.

``SurfaceRays(vertices, faces).first_hit(origins, ends, skip)`` returns, for every segment
``origin -> end``, the fraction along it of the first triangle crossing (``inf`` when none),
ignoring the triangles that contain the segment's own start vertex (``skip``), so a ray cast
from a surface vertex never hits the surface it starts on. The kernels are numba-compiled and
cached on disk; without numba a vectorised numpy path (cKDTree culling, Moller-Trumbore on
candidate pairs) gives the same answers, slower. No Python loop runs over vertices.

The BVH sorts triangles along a Morton curve of their centroids and splits each range at its
middle (a linear BVH), leaves of at most ``LEAF`` triangles; built in about 0.1 s for 200k
triangles.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..model.skinning_kernels import disabled as _numba_disabled

try:  # numba is optional: the numpy path below is the reference and the fallback
    if _numba_disabled():  # RIGEDIT_NO_NUMBA=1, as for the skinning kernels
        raise ImportError
    import numba
except ImportError:  # pragma: no cover - exercised on machines without numba
    numba = None

__all__ = ["SurfaceRays", "HAVE_NUMBA", "warm"]

LEAF = 4
BLOCK = 256
HAVE_NUMBA = numba is not None


def _morton_order(centroids):
    lo = centroids.min(axis=0)
    ext = np.maximum(centroids.max(axis=0) - lo, 1e-300)
    q = np.minimum(((centroids - lo) / ext * 1023.0).astype(np.uint64), 1023)

    def spread(x):  # interleave 10 bits with two zero bits between them
        x = (x | (x << np.uint64(16))) & np.uint64(0x030000FF)
        x = (x | (x << np.uint64(8))) & np.uint64(0x0300F00F)
        x = (x | (x << np.uint64(4))) & np.uint64(0x030C30C3)
        x = (x | (x << np.uint64(2))) & np.uint64(0x09249249)
        return x
    code = (spread(q[:, 0]) << np.uint64(2)) | (spread(q[:, 1]) << np.uint64(1)) | spread(q[:, 2])
    return np.argsort(code, kind="stable")


def _build_py(tri_lo, tri_hi, leaf):
    """Nodes of a midpoint-split tree over the sorted triangle range (numba or plain)."""
    t = len(tri_lo)
    cap = 4 * (t // leaf + 1) + 1  # leaves hold between leaf/2 and leaf triangles
    lo = np.zeros(cap, np.int64)
    hi = np.zeros(cap, np.int64)
    left = np.full(cap, -1, np.int64)
    bmin = np.zeros((cap, 3))
    bmax = np.zeros((cap, 3))
    lo[0], hi[0] = 0, t
    count = 1
    i = 0
    while i < count:  # breadth first: children always come after their parent
        if hi[i] - lo[i] > leaf:
            mid = (lo[i] + hi[i]) // 2
            left[i] = count
            lo[count], hi[count] = lo[i], mid
            lo[count + 1], hi[count + 1] = mid, hi[i]
            count += 2
        i += 1
    for k in range(count - 1, -1, -1):
        if left[k] < 0:
            for d in range(3):
                bmin[k, d] = tri_lo[lo[k]:hi[k], d].min()
                bmax[k, d] = tri_hi[lo[k]:hi[k], d].max()
        else:
            for d in range(3):
                bmin[k, d] = min(bmin[left[k], d], bmin[left[k] + 1, d])
                bmax[k, d] = max(bmax[left[k], d], bmax[left[k] + 1, d])
    return lo[:count], hi[:count], left[:count], bmin[:count], bmax[:count]


def _first_hit_py(orig, end, skip, rpart, tv, tpart, p0, e1, e2, lo, hi, left, bmin, bmax,
                  t_lo, t_hi, front, any_hit, out):
    """Loop kernel of :meth:`SurfaceRays.first_hit` (numba-compiled when available).

    Rays go in blocks of ``BLOCK``, one traversal stack per block.
    """
    nblocks = (orig.shape[0] + BLOCK - 1) // BLOCK
    for blk in range(nblocks):
        _block(blk * BLOCK, min(orig.shape[0], (blk + 1) * BLOCK), orig, end, skip, rpart, tv,
               tpart, p0, e1, e2, lo, hi, left, bmin, bmax, t_lo, t_hi, front, any_hit, out)
    return out


def _block_py(r0, r1, orig, end, skip, rpart, tv, tpart, p0, e1, e2, lo, hi, left, bmin, bmax,
              t_lo, t_hi, front, any_hit, out):
    stack = np.empty(128, np.int64)
    for r in range(r0, r1):
        ox, oy, oz = orig[r, 0], orig[r, 1], orig[r, 2]
        dx, dy, dz = end[r, 0] - ox, end[r, 1] - oy, end[r, 2] - oz
        ix = 1.0 / dx if dx != 0.0 else 1e300
        iy = 1.0 / dy if dy != 0.0 else 1e300
        iz = 1.0 / dz if dz != 0.0 else 1e300
        s = skip[r]
        rp = rpart[r]
        best = np.inf
        stack[0] = 0
        top = 1
        while top > 0:
            top -= 1
            k = stack[top]
            # slab test of the parameter range [t_lo, min(best, t_hi)] against the box
            a0 = (bmin[k, 0] - ox) * ix
            a1 = (bmax[k, 0] - ox) * ix
            tn = min(a0, a1)
            tf = max(a0, a1)
            a0 = (bmin[k, 1] - oy) * iy
            a1 = (bmax[k, 1] - oy) * iy
            tn = max(tn, min(a0, a1))
            tf = min(tf, max(a0, a1))
            a0 = (bmin[k, 2] - oz) * iz
            a1 = (bmax[k, 2] - oz) * iz
            tn = max(tn, min(a0, a1))
            tf = min(tf, max(a0, a1))
            if tn > tf or tf < t_lo or tn > min(best, t_hi):
                continue
            if left[k] >= 0:
                stack[top] = left[k]
                stack[top + 1] = left[k] + 1
                top += 2
                continue
            for m in range(lo[k], hi[k]):
                if tv[m, 0] == s or tv[m, 1] == s or tv[m, 2] == s:
                    continue
                if rp >= 0 and tpart[m] != rp:
                    continue
                # Moller-Trumbore; det > 0 when the segment enters the triangle's front side
                px = dy * e2[m, 2] - dz * e2[m, 1]
                py = dz * e2[m, 0] - dx * e2[m, 2]
                pz = dx * e2[m, 1] - dy * e2[m, 0]
                det = e1[m, 0] * px + e1[m, 1] * py + e1[m, 2] * pz
                if det == 0.0 or (front and det < 0.0):
                    continue
                inv = 1.0 / det
                qx, qy, qz = ox - p0[m, 0], oy - p0[m, 1], oz - p0[m, 2]
                u = (qx * px + qy * py + qz * pz) * inv
                if u < 0.0 or u > 1.0:
                    continue
                cx = qy * e1[m, 2] - qz * e1[m, 1]
                cy = qz * e1[m, 0] - qx * e1[m, 2]
                cz = qx * e1[m, 1] - qy * e1[m, 0]
                v = (dx * cx + dy * cy + dz * cz) * inv
                if v < 0.0 or u + v > 1.0:
                    continue
                t = (e2[m, 0] * cx + e2[m, 1] * cy + e2[m, 2] * cz) * inv
                if t_lo < t < t_hi and t < best:
                    best = t
            if any_hit and best < np.inf:
                break
        out[r] = best


if HAVE_NUMBA:
    _build = numba.njit(cache=True)(_build_py)
    _block = numba.njit(cache=True, nogil=True)(_block_py)
    # Serial on purpose: numba's default (workqueue) threading layer refuses a parallel
    # kernel launched from two threads at once, and the editor runs weights in a worker
    # thread while its skinning kernels run on the main thread. nogil lets the UI run.
    _first_hit = numba.njit(cache=True, nogil=True)(_first_hit_py)
else:  # pragma: no cover
    _build = _build_py
    _first_hit = None


def _first_hit_numpy(orig, end, skip, rpart, tv, tpart, p0, e1, e2, radius, tree, t_lo, t_hi,
                     front, chunk=2048):
    """Vectorised reference: candidate triangles by a ball around each segment."""
    out = np.full(len(orig), np.inf)
    for a in range(0, len(orig), chunk):
        o, e, s = orig[a:a + chunk], end[a:a + chunk], skip[a:a + chunk]
        rp = rpart[a:a + chunk]
        mid = 0.5 * (o + e)
        reach = 0.5 * np.linalg.norm(e - o, axis=1) + radius
        lists = tree.query_ball_point(mid, reach)
        counts = np.fromiter((len(x) for x in lists), np.int64, len(lists))
        if counts.sum() == 0:
            continue
        r = np.repeat(np.arange(len(o)), counts)
        m = np.concatenate([np.asarray(x, dtype=np.int64) for x in lists])
        keep = np.all(tv[m] != s[r][:, None], axis=1) & ((rp[r] < 0) | (tpart[m] == rp[r]))
        r, m = r[keep], m[keep]
        d = e[r] - o[r]
        p = np.cross(d, e2[m])
        det = np.einsum("ij,ij->i", e1[m], p)
        ok = (det > 0.0) if front else (det != 0.0)
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        q = o[r] - p0[m]
        u = np.einsum("ij,ij->i", q, p) * inv
        c = np.cross(q, e1[m])
        v = np.einsum("ij,ij->i", d, c) * inv
        t = np.einsum("ij,ij->i", e2[m], c) * inv
        hit = ok & (u >= 0) & (u <= 1) & (v >= 0) & (u + v <= 1) & (t > t_lo) & (t < t_hi)
        np.minimum.at(out, a + r[hit], t[hit])
    return out


class SurfaceRays:
    """Segment queries against a triangle surface.

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int64
    use_numba : bool, optional
        Force the compiled (True) or numpy (False) path; default: compiled when available.
    parts : (F,) int, optional
        A part id per triangle, for segments that only test the triangles of their own part
        (``first_hit(..., part=...)``).
    """

    def __init__(self, vertices, faces, use_numba=None, parts=None):
        vertices = np.ascontiguousarray(vertices, dtype=np.float64)
        faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
        self.use_numba = HAVE_NUMBA if use_numba is None else (use_numba and HAVE_NUMBA)
        self.empty = len(faces) == 0
        if self.empty:
            return
        corners = vertices[faces]                                    # (F, 3, 3)
        order = _morton_order(corners.mean(axis=1))
        corners = corners[order]
        self.tv = np.ascontiguousarray(faces[order])
        self.tpart = (np.zeros(len(faces), np.int64) if parts is None
                      else np.ascontiguousarray(np.asarray(parts, np.int64)[order]))
        self.p0 = np.ascontiguousarray(corners[:, 0])
        self.e1 = np.ascontiguousarray(corners[:, 1] - corners[:, 0])
        self.e2 = np.ascontiguousarray(corners[:, 2] - corners[:, 0])
        if self.use_numba:
            self.nodes = _build(np.ascontiguousarray(corners.min(axis=1)),
                                np.ascontiguousarray(corners.max(axis=1)), LEAF)
        else:
            centre = corners.mean(axis=1)
            self.radius = float(np.linalg.norm(corners - centre[:, None], axis=2).max())
            self.tree = cKDTree(centre)
            self.centre = centre

    def first_hit(self, origins, ends, skip=None, t_lo=0.0, t_hi=1.0, front_only=False,
                  any_hit=False, part=None):
        """Where each segment first crosses the surface.

        Parameters
        ----------
        origins, ends : (N, 3) float64
        skip : (N,) int, optional
            A vertex index per segment; triangles using it are ignored (-1: none).
        t_lo, t_hi : float
            Only crossings with ``t_lo < t < t_hi`` count (``t`` = fraction along the segment).
        front_only : bool
            Count only crossings that enter a triangle from its front (normal) side.
        any_hit : bool
            Stop at the first crossing found rather than the nearest (for a yes/no test).
        part : (N,) int, optional
            Test only the triangles of this part (the ``parts`` given at construction) for
            each segment; -1 or omitted: every triangle.

        Returns
        -------
        t : (N,) float64
            Fraction of the first crossing, ``inf`` where there is none.
        """
        origins = np.ascontiguousarray(origins, dtype=np.float64).reshape(-1, 3)
        ends = np.ascontiguousarray(ends, dtype=np.float64).reshape(-1, 3)
        skip = (np.full(len(origins), -1, np.int64) if skip is None
                else np.ascontiguousarray(skip, dtype=np.int64))
        if self.empty or len(origins) == 0:
            return np.full(len(origins), np.inf)
        part = (np.full(len(origins), -1, np.int64) if part is None
                else np.ascontiguousarray(part, dtype=np.int64))
        if self.use_numba:
            out = np.empty(len(origins))
            return _first_hit(origins, ends, skip, part, self.tv, self.tpart, self.p0, self.e1,
                              self.e2, *self.nodes[:3], *self.nodes[3:], float(t_lo),
                              float(t_hi), bool(front_only), bool(any_hit), out)
        return _first_hit_numpy(origins, ends, skip, part, self.tv, self.tpart, self.p0,
                                self.e1, self.e2, self.radius, self.tree, t_lo, t_hi,
                                front_only)

    def blocked(self, origins, ends, skip=None, t_lo=0.0, t_hi=1.0, front_only=False,
                part=None):
        """(N,) bool: the segment crosses the surface strictly between ``t_lo`` and ``t_hi``
        (only the triangles of its ``part`` when given, as for :meth:`first_hit`)."""
        return np.isfinite(self.first_hit(origins, ends, skip, t_lo, t_hi, front_only,
                                          any_hit=True, part=part))


def warm():
    """Compile (or load from numba's disk cache) the kernels on a tiny mesh, so the first
    real use does not wait for the compiler (``dev.py`` calls this after installing)."""
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    f = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
    return SurfaceRays(v, f).first_hit([[0.2, 0.2, -1.0]], [[0.2, 0.2, 1.0]])
