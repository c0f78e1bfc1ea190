"""A watertight proxy of the volume of any triangle mesh: open, soup, overlapping parts.

The embedding needs an inside (ray parity, medial spheres). Game characters and generated
assets rarely have one: parts modelled apart and pushed into each other (parity is even,
"outside", where two closed shells overlap), eye and neck seams left open, boxes without
caps, interior faces, triangle soup. This module rebuilds the volume on a grid, without
trusting the surface's orientation or connectivity, and returns a closed triangle mesh of
it for the embedding (the skin weights stay on the real mesh):

1. **Shell**: the cells the surface passes through (those holding a point of a dense
   sampling of it, a third of a cell apart).
2. **Ray stabbing** (after Nooruddin and Turk, "Simplification and repair of polygonal
   models using volumetric techniques", 2003): along each of the 13 line directions of the
   grid (3 axes, 6 face and 4 body diagonals), a cell votes "inside" when the shell lies
   beyond it both ways. A cell enclosed by a surface gets all 13 votes; a hole, an open end
   or a missing cap only lets a few lines through, while the space in a concavity (between
   the legs, under an arm) sees open space along most lines. A cell is inside with at least
   :data:`MIN_VOTES` votes. Overlaps and interior faces are simply inside; a sheet with
   nothing behind it (a cape, a fin) has no volume and drops out.
3. **Islands**: enclosed voids are filled; inside pieces under :data:`MIN_ISLAND` of the
   volume (a loose button) are dropped (they keep their skin weights through the real
   mesh). No volume, or one whose boundary takes in under :data:`MIN_COVERED` of the
   surface (what an open shell leaves: its corners), is :class:`NoVolumeError`.
4. **Surface** (naive surface nets): the signed distance (the distance from a cell centre
   to the nearest surface sample, signed by the vote) crosses zero on grid edges; each cube the zero crosses gets a vertex at the mean
   of its crossings, each crossed edge a quad of the four cubes round it, facing out. The
   surface lies on the real one where that was closed (within the sampling's error, about a
   tenth of a cell) and caps holes half-way between the votes that differ.

Pure numpy and scipy (no VTK: the embedding runs headless).
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from ..binding.laplacian import face_areas
from .distance import surface_samples

__all__ = ["VolumeProxy", "volume_proxy", "NoVolumeError", "RESOLUTION", "MIN_VOTES",
           "MIN_ISLAND", "MIN_COVERED", "DIRECTIONS"]

#: Cells along the longest side of the bounding box. Finer than the embedding's own field
#: (128), so the proxy's surface is not what limits it: a 1.8 m figure gets 9 mm cells.
RESOLUTION = 192
PAD = 3
#: At most about this many cells on the surface: a blob filling its box (no thin limbs to
#: resolve) gets coarser cells, which bounds the cost (a sphere: 116k at 192 cells across).
MAX_SURFACE_CELLS = 60_000
#: Of the 13 lines through a cell, how many must meet the shell on both sides for "inside".
MIN_VOTES = 9
#: Inside pieces smaller than this fraction of the whole volume are dropped.
MIN_ISLAND = 0.01
#: A volume whose boundary takes in less than this share of the surface is no body (the
#: front half of a character, a mask: 20%; the Mixamo Xbot, its joint shells inside: 79%).
MIN_COVERED = 0.3
#: The 13 line directions of the grid (one of each +/- pair).
DIRECTIONS = np.array([d for d in np.ndindex(3, 3, 3)]) - 1
DIRECTIONS = DIRECTIONS[[tuple(d) > (0, 0, 0) for d in map(tuple, DIRECTIONS)]]


class NoVolumeError(ValueError):
    """The surface encloses no volume, even with its holes closed (a sheet, a point cloud)."""


@dataclass
class VolumeProxy:
    """A closed triangle mesh of a mesh's volume.

    Attributes
    ----------
    vertices : (P, 3) float64
        In the input's frame and units.
    faces : (Q, 3) int64
        Closed (every edge shared by an even number of triangles), facing out.
    h : float
        Grid cell size.
    volume : float
        Volume of the inside cells kept.
    islands_dropped : int
        Inside pieces left out for being under ``MIN_ISLAND`` of the volume.
    pieces : int
        Inside pieces kept.
    largest : float
        The largest inside piece's share of the kept volume (1.0 for one piece).
    seconds : float
        Wall time to build it.
    covered : float
        Share of the mesh's surface (of its samples) within a cell of the proxy's.
    """

    vertices: np.ndarray
    faces: np.ndarray
    h: float
    volume: float
    islands_dropped: int = 0
    pieces: int = 1
    largest: float = 1.0
    seconds: float = 0.0
    covered: float = 1.0


def _shift(a, s):
    """``a`` (2-D) shifted so that out[u, v] = a[u + s[0], v + s[1]], False beyond its edge."""
    out = np.zeros_like(a)
    src = tuple(slice(max(k, 0), a.shape[i] + min(k, 0)) for i, k in enumerate(s))
    dst = tuple(slice(max(-k, 0), a.shape[i] + min(-k, 0)) for i, k in enumerate(s))
    out[dst] = a[src]
    return out


def _beyond(shell, step):
    """(NX, NY, NZ) bool: a shell cell lies one or more ``step``s beyond each cell.

    Swept slice by slice along an axis the step moves on, from the far end: a cell's answer
    is its next cell's shell flag or that cell's answer.
    """
    a = int(np.flatnonzero(step)[0])
    others = [k for k in range(3) if k != a]
    s_shell = np.moveaxis(shell, a, 0)
    out = np.zeros_like(shell)
    s_out = np.moveaxis(out, a, 0)              # a view: writing it fills ``out``
    n = s_shell.shape[0]
    sa = int(step[a])
    lateral = (int(step[others[0]]), int(step[others[1]]))
    for i in (range(n - 2, -1, -1) if sa > 0 else range(1, n)):
        nxt = s_shell[i + sa] | s_out[i + sa]
        s_out[i] = _shift(nxt, lateral) if any(lateral) else nxt
    return out


def _votes(shell):
    """(NX, NY, NZ) int8: of the 13 grid lines through each cell, how many meet the shell
    on both sides."""
    votes = np.zeros(shell.shape, np.int8)
    for d in DIRECTIONS:
        votes += _beyond(shell, d) & _beyond(shell, -d)
    return votes


def _surface_nets(phi, origin, h):
    """Closed mesh of the zero set of ``phi`` (inside where > 0), naive surface nets.

    Parameters
    ----------
    phi : (NX, NY, NZ) float64
        Signed distance, positive inside; the outermost layer of cells must be outside.
    origin : (3,) float64
    h : float

    Returns
    -------
    vertices : (P, 3) float64
    faces : (Q, 3) int64
    """
    inside = phi > 0
    cubes = np.array(phi.shape) - 1
    total = int(np.prod(cubes))
    acc = np.zeros((total, 3))
    cnt = np.zeros(total)
    quads = []
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        lo = [slice(None)] * 3
        hi = [slice(None)] * 3
        lo[a], hi[a] = slice(0, -1), slice(1, None)
        p0, p1 = phi[tuple(lo)], phi[tuple(hi)]
        cross = inside[tuple(lo)] != inside[tuple(hi)]
        idx = np.argwhere(cross)                       # grid point at the edge's low end
        f0, f1 = p0[cross], p1[cross]
        den = f0 - f1
        t = np.clip(np.divide(f0, den, out=np.full_like(f0, 0.5), where=den != 0), 0.0, 1.0)
        point = idx.astype(np.float64)
        point[:, a] += t
        # the four cubes round the edge, in turn about +a (b then c: right-handed)
        ring = []
        for du, dv in ((0, 0), (1, 0), (1, 1), (0, 1)):
            q = idx.copy()
            q[:, b] -= du
            q[:, c] -= dv
            ring.append(np.ravel_multi_index(q.T, cubes))
        ring = np.stack(ring, axis=1)
        for k in range(3):
            acc[:, k] += np.bincount(ring.ravel(), np.repeat(point[:, k], 4), minlength=total)
        cnt += np.bincount(ring.ravel(), minlength=total)
        out_up = inside[tuple(idx.T)]                  # inside at the low end: faces +a
        ring[~out_up] = ring[~out_up][:, ::-1]
        quads.append(ring)
    quads = np.concatenate(quads)
    used = np.flatnonzero(cnt)
    remap = np.full(total, -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    vertices = origin + acc[used] / cnt[used, None] * h
    q = remap[quads]
    faces = np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])
    return vertices, faces


def volume_proxy(vertices, faces, resolution=RESOLUTION, min_votes=MIN_VOTES, seed=0):
    """Build the :class:`VolumeProxy` of any triangle mesh (see the module notes).

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int
        Any orientation, shared vertices or not, any number of parts.
    resolution : int
        Cells along the longest side of the bounding box (fewer when the surface would
        cross more than ``MAX_SURFACE_CELLS`` of them).
    min_votes : int
        Of 13, the lines that must meet the surface on both sides of an inside cell.
    seed : int
        Seed of the surface sampling (deterministic for a given seed).

    Returns
    -------
    VolumeProxy

    Raises
    ------
    NoVolumeError
        Nothing is enclosed: a flat or open sheet, a scatter of points or slivers.
    """
    t0 = time.perf_counter()
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    # only the vertices of faces: a loose vertex is no surface (and would be sampled)
    used, faces = np.unique(faces, return_inverse=True)
    vertices, faces = vertices[used], faces.reshape(-1, 3)
    if len(faces) == 0:
        raise NoVolumeError("no faces")
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    area = float(face_areas(vertices, faces).sum())
    h = max(float((hi - lo).max()) / resolution, np.sqrt(area / MAX_SURFACE_CELLS))
    if not h > 0:
        raise NoVolumeError("all vertices at one point")
    origin = lo - PAD * h
    shape = tuple(int(s) for s in np.ceil((hi - lo) / h).astype(np.int64) + 2 * PAD + 1)
    dense = surface_samples(vertices, faces, h / 3.0, np.random.default_rng(seed))
    cell = np.clip(np.rint((dense - origin) / h).astype(np.int64), 0, np.array(shape) - 1)
    shell = np.zeros(shape, bool)
    shell[tuple(cell.T)] = True
    # enclosed voids are inside (a line slipping through the sampling's gaps can leave one)
    inside = ndimage.binary_fill_holes(_votes(shell) >= min_votes)
    labels, n = ndimage.label(inside)
    if n == 0:
        raise NoVolumeError("the surface encloses no volume, even with its holes closed "
                            "(a flat or open sheet?)")
    sizes = np.bincount(labels.ravel(), minlength=n + 1)[1:]
    keep = sizes >= MIN_ISLAND * sizes.sum()
    inside = keep[labels - 1] & (labels > 0)
    volume = float(sizes[keep].sum()) * h ** 3
    extent = np.ptp(vertices, axis=0)
    if sizes[keep].sum() < 8 or volume < 1e-4 * float(np.prod(np.maximum(extent, h))):
        raise NoVolumeError("the surface encloses almost no volume, even with its holes "
                            "closed (a flat or open sheet?)")
    # The share of the surface samples on the volume's boundary (in a cell beside it): a
    # body's skin is nearly all there; an open shell's leftovers (the corners of a mask)
    # take in little of it.
    edge = ndimage.binary_dilation(inside) & ~ndimage.binary_erosion(inside)
    covered = float(np.mean(ndimage.binary_dilation(edge)[tuple(cell.T)]))
    if covered < MIN_COVERED:
        raise NoVolumeError(f"only {100 * covered:.0f}% of the surface bounds the little "
                            f"volume it encloses (at least {100 * MIN_COVERED:.0f}% expected): "
                            "an open shell or sheet")
    # Only cells on either side of the inside's boundary need their distance: the zero
    # crossings are interpolated between them (the k-d tree query is the costly step).
    idx = np.argwhere(edge)
    far = 3.0 * h
    dist, _ = cKDTree(dense).query(origin + idx * h, distance_upper_bound=far, workers=1)
    phi = np.where(inside, far, -far)
    phi[tuple(idx.T)] = np.where(inside[tuple(idx.T)], 1.0, -1.0) * np.clip(dist, 1e-6 * h, far)
    pv, pf = _surface_nets(phi, origin, h)
    return VolumeProxy(pv, pf, h, volume, int((~keep).sum()), int(keep.sum()),
                       float(sizes[keep].max() / sizes[keep].sum()),
                       time.perf_counter() - t0, covered)
