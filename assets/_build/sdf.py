"""Signed distance primitives blended with a smooth minimum, meshed with VTK.

A character is a list of :class:`Prim` (round cones and ellipsoids), each owned by the joint
whose bone it dresses. The same primitives later give the skinning weights (a vertex belongs
most to the primitives it lies on).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Prim:
    """One primitive. kind 'cone': a, b end points, r1, r2 radii. kind 'ell': centre a,
    radii r (3,), rotation rot (3x3, columns = local axes in model space)."""
    kind: str
    owner: str
    a: np.ndarray
    b: np.ndarray = None
    r1: float = 0.0
    r2: float = 0.0
    radii: np.ndarray = None
    rot: np.ndarray = None
    blend: float = 0.03
    pts: np.ndarray = None      # kind 'chain': centreline samples (N, 3)
    rads: np.ndarray = None     # kind 'chain': radius per sample (N,)
    squash: tuple = None        # kind 'chain': (axis, along, spline) axis scaled by s(p[along])
    role: str = "both"          # 'mesh': shape only, 'weights': skinning only, 'both'

    def bounds(self):
        if self.kind == "chain":
            r = self.rads[:, None]
            lo, hi = np.min(self.pts - r, axis=0), np.max(self.pts + r, axis=0)
            if self.squash is not None:
                ax, _, spl = self.squash
                smax = float(np.max(spl(np.linspace(spl.x[0], spl.x[-1], 200))))
                lo[ax], hi[ax] = lo[ax] * max(smax, 1.0), hi[ax] * max(smax, 1.0)
            return lo - self.blend, hi + self.blend
        if self.kind == "cone":
            r = max(self.r1, self.r2)
            lo = np.minimum(self.a, self.b) - r
            hi = np.maximum(self.a, self.b) + r
        else:
            r = float(np.max(self.radii))
            lo, hi = self.a - r, self.a + r
        return lo - self.blend, hi + self.blend

    def sdf(self, p):
        """(N,) signed distance of points (N, 3) (approximate for ellipsoids)."""
        if self.kind == "cone":
            return round_cone(p, self.a, self.b, self.r1, self.r2)
        if self.kind == "chain":
            return chain_sdf(p, self.pts, self.rads, self.squash)
        q = (p - self.a) @ self.rot
        k0 = np.linalg.norm(q / self.radii, axis=-1)
        k1 = np.linalg.norm(q / (self.radii * self.radii), axis=-1)
        return k0 * (k0 - 1.0) / np.maximum(k1, 1e-12)


def cone(owner, a, b, r1, r2=None, blend=0.03):
    return Prim("cone", owner, np.asarray(a, float), np.asarray(b, float), float(r1),
                float(r1 if r2 is None else r2), blend=blend)


def ell(owner, centre, radii, axis_z=None, blend=0.03, axis_y=(0, 1, 0)):
    """Ellipsoid with its local z axis along ``axis_z`` (default model z)."""
    z = np.array([0, 0, 1.0] if axis_z is None else axis_z, float)
    z /= np.linalg.norm(z)
    y = np.asarray(axis_y, float)
    x = np.cross(y, z)
    if np.linalg.norm(x) < 1e-6:
        x = np.array([1.0, 0, 0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return Prim("ell", owner, np.asarray(centre, float), radii=np.asarray(radii, float),
                rot=np.stack([x, y, z], axis=1), blend=blend)


def sweep(owners, ctrl, radii, squash=None, blend=0.05, seg_len=0.03):
    """A smooth variable-radius tube: a cubic spline through the control points ``ctrl``
    with radii interpolated by a cubic spline too, sampled into short round cones whose union
    (a hard minimum, so no bulge where two meet) is one continuous smooth surface.

    ``owners``: one joint name per control interval (len(ctrl) - 1), used for the weights.
    ``squash``: optional (axis, along, knots, values): the section is scaled along ``axis``
    by a smooth function of the coordinate ``along`` (an elliptic, varying section).
    Returns one prim for the shape and one weight-only prim per owner run.
    """
    from scipy.interpolate import CubicSpline

    ctrl = np.asarray(ctrl, float)
    t = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(ctrl, axis=0), axis=1))])
    cs = CubicSpline(t, ctrl, bc_type="natural")
    rs = CubicSpline(t, np.asarray(radii, float), bc_type="natural")
    n = max(int(np.ceil(t[-1] / seg_len)), 2)
    ts = np.linspace(0, t[-1], n + 1)
    pts, rads = cs(ts), rs(ts)
    sq = None
    if squash is not None:
        axis, along, knots, values = squash
        sq = (axis, along, CubicSpline(knots, values, bc_type="clamped"))
    out = [Prim("chain", owners[0], a=pts[0], pts=pts, rads=rads, squash=sq, blend=blend,
                role="mesh")]
    seg_owner = [owners[min(np.searchsorted(t, 0.5 * (ts[i] + ts[i + 1])) - 1,
                            len(owners) - 1)] for i in range(n)]
    i = 0
    while i < n:
        j = i
        while j < n and seg_owner[j] == seg_owner[i]:
            j += 1
        out.append(Prim("chain", seg_owner[i], a=pts[i], pts=pts[i:j + 1], rads=rads[i:j + 1],
                        squash=sq, blend=blend, role="weights"))
        i = j
    return out


def chain_sdf(p, pts, rads, squash=None):
    """Union (hard minimum) of the round cones between consecutive samples."""
    p = np.asarray(p, float)
    if squash is not None:
        axis, along, spl = squash
        s = spl(np.clip(p[:, along], spl.x[0], spl.x[-1]))
        p = p.copy()
        p[:, axis] /= s
    out = np.full(len(p), np.inf)
    margin = 0.2
    for i in range(len(pts) - 1):
        a, b, r1, r2 = pts[i], pts[i + 1], rads[i], rads[i + 1]
        r = max(r1, r2) + margin
        lo, hi = np.minimum(a, b) - r, np.maximum(a, b) + r
        m = np.all((p >= lo) & (p <= hi), axis=1)
        if not m.any():
            continue
        idx = np.nonzero(m)[0]
        out[idx] = np.minimum(out[idx], round_cone(p[idx], a, b, r1, r2))
    far = ~np.isfinite(out)
    if far.any():
        # Outside every segment's box: at least ``margin`` away, which is all a field that
        # only matters within a blend width of the surface needs; few points: exact.
        q = p[far]
        if len(q) * len(pts) <= 4_000_000:
            out[far] = np.min(np.linalg.norm(q[:, None, :] - pts[None], axis=-1) - rads, axis=1)
        else:
            out[far] = margin
    return out


def round_cone(p, a, b, r1, r2):
    """Exact distance to a round cone (capsule with two radii), after Inigo Quilez."""
    ba = b - a
    l2 = float(ba @ ba)
    rr = r1 - r2
    a2 = l2 - rr * rr
    il2 = 1.0 / l2
    pa = p - a
    y = pa @ ba
    z = y - l2
    x2 = np.sum((pa * l2 - np.outer(y, ba)) ** 2, axis=1)
    y2 = y * y * l2
    z2 = z * z * l2
    k = np.sign(rr) * rr * rr * x2
    d3 = (np.sqrt(np.maximum(x2 * a2 * il2, 0)) + y * rr) * il2 - r1
    d1 = np.sqrt(x2 + z2) * il2 - r2
    d2 = np.sqrt(x2 + y2) * il2 - r1
    out = np.where(np.sign(y) * a2 * y2 < k, d2, d3)
    return np.where(np.sign(z) * a2 * z2 > k, d1, out)


def smin(a, b, k):
    """Polynomial smooth minimum with blend width k."""
    h = np.maximum(k - np.abs(a - b), 0.0) / k
    return np.minimum(a, b) - h * h * k * 0.25


def field_on_grid(prims, spacing, pad=0.05):
    """Evaluate the blended field on a regular grid; only each primitive's box is touched."""
    lo = np.min([p.bounds()[0] for p in prims], axis=0) - pad
    hi = np.max([p.bounds()[1] for p in prims], axis=0) + pad
    dims = np.ceil((hi - lo) / spacing).astype(int) + 1
    field = np.full(dims, 1.0, dtype=np.float64)
    axes = [lo[i] + spacing * np.arange(dims[i]) for i in range(3)]
    for prim in prims:
        plo, phi = prim.bounds()
        i0 = np.maximum(np.floor((plo - lo) / spacing).astype(int), 0)
        i1 = np.minimum(np.ceil((phi - lo) / spacing).astype(int) + 1, dims)
        sub = np.stack(np.meshgrid(*[axes[i][i0[i]:i1[i]] for i in range(3)], indexing="ij"),
                       axis=-1).reshape(-1, 3)
        d = prim.sdf(sub).reshape(tuple(i1 - i0))
        view = field[i0[0]:i1[0], i0[1]:i1[1], i0[2]:i1[2]]
        view[...] = smin(view, d, prim.blend)
    return field, lo, dims


def mesh_from_prims(prims, spacing, target_vertices, smooth_iters=30):
    """Closed, manifold, outward-oriented triangle mesh of the blended primitives.

    Returns vertices (V, 3) float64, faces (F, 3) int64.
    """
    import pyvista as pv
    import vtk

    field, lo, dims = field_on_grid(prims, spacing)
    grid = pv.ImageData(dimensions=tuple(dims), spacing=(spacing,) * 3, origin=tuple(lo))
    grid.point_data["d"] = field.ravel(order="F")
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(grid)
    fe.SetValue(0, 0.0)
    fe.ComputeNormalsOff()
    fe.Update()
    surf = pv.wrap(fe.GetOutput()).clean().triangulate()
    surf = surf.connectivity("largest").clean()
    surf = surf.smooth_taubin(n_iter=smooth_iters, pass_band=0.05)
    # Decimate to the target size, then a last gentle smoothing to even out the triangles.
    ratio = 1.0 - min(1.0, 2.0 * target_vertices / surf.n_cells)
    dec = vtk.vtkQuadricDecimation()
    dec.SetInputData(surf)
    dec.SetTargetReduction(ratio)
    dec.VolumePreservationOn()
    dec.Update()
    surf = pv.wrap(dec.GetOutput()).clean().triangulate()
    surf = surf.smooth_taubin(n_iter=20, pass_band=0.1)
    verts = np.asarray(surf.points, dtype=np.float64)
    faces = surf.faces.reshape(-1, 4)[:, 1:].astype(np.int64)
    verts, faces = fix_mesh(verts, faces)
    return verts, faces


def edge_report(faces):
    """Counts of boundary edges, non-manifold edges and orientation conflicts."""
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    und = np.sort(e, axis=1)
    _, cnt = np.unique(und, axis=0, return_counts=True)
    _, dcnt = np.unique(e, axis=0, return_counts=True)
    return {"boundary": int(np.sum(cnt == 1)), "nonmanifold": int(np.sum(cnt > 2)),
            "directed_dup": int(np.sum(dcnt > 1))}


def signed_volume(verts, faces):
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def fix_mesh(verts, faces):
    """Drop degenerate faces and unused vertices, orient outward; raise if not manifold."""
    keep = ((faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2])
            & (faces[:, 0] != faces[:, 2]))
    faces = faces[keep]
    used = np.zeros(len(verts), bool)
    used[faces.ravel()] = True
    remap = np.cumsum(used) - 1
    verts, faces = verts[used], remap[faces]
    if signed_volume(verts, faces) < 0:
        faces = faces[:, ::-1].copy()
    return verts, faces
