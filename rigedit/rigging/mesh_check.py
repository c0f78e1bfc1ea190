"""Read and check a mesh to be auto-rigged: is it closed enough to have an inside?

The embedding needs an inside and an outside (a distance field, medial spheres). A mesh
qualifies when, after welding coincident vertices (glTF and OBJ split them at UV seams):

- it has faces (a point cloud has no inside);
- it is closed or nearly so: every hole (a loop of boundary edges) is at most
  :data:`MAX_HOLE` (10%) of the mesh's size across (its largest bounding-box side; a hole's
  width is its perimeter / pi, a circle's diameter), and the holes together would be covered
  by discs of at most :data:`MAX_OPEN_AREA` (5%) of the surface area: an open neck or eye
  socket passes, a mesh without a back or a loose sheet does not;
- at most :data:`MAX_NONMANIFOLD` (2%) of its edges are shared by more than two triangles
  (a few are harmless; many mean a triangle soup with no consistent surface);
- one body dominates: parts (connected pieces) are fine, eyes, teeth or buttons ride along,
  but the largest part must hold at least :data:`MIN_MAIN_PART` (10%) of the surface area
  (below that it is a scatter of pieces, not a character).

Parts under :data:`SMALL_PART` (1%) of the area are left out of the embedding (they get
skin weights like the rest); everything else is embedded as one volume.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..errors import RigFileError
from ..model import laplacian as lap
from ..model.heat import WELD  # welded as the heat weights weld it

__all__ = ["MeshCheck", "read_mesh", "check_mesh", "MAX_HOLE", "MAX_OPEN_AREA",
           "MAX_NONMANIFOLD", "MIN_MAIN_PART", "SMALL_PART"]

MAX_HOLE = 0.10
MAX_OPEN_AREA = 0.05
MAX_NONMANIFOLD = 0.02
MIN_MAIN_PART = 0.10
SMALL_PART = 0.01


@dataclass
class MeshCheck:
    """What :func:`check_mesh` found.

    Attributes
    ----------
    vertices, faces : (W, 3) float64, (F', 3) int64
        The welded mesh, degenerate and repeated triangles dropped.
    body : (F',) bool
        Faces of the parts that go into the embedding (parts of at least ``SMALL_PART``).
    size : float
        Largest side of the bounding box.
    holes : list[float]
        Each hole's width (perimeter / pi) as a fraction of ``size``, largest first.
    open_area : float
        Area of discs covering the holes, as a fraction of the surface area.
    nonmanifold : int
        Edges shared by more than two triangles.
    edges : int
    part_shares : list[float]
        Each part's share of the surface area, largest first.
    """

    vertices: np.ndarray
    faces: np.ndarray
    body: np.ndarray
    size: float
    holes: list = field(default_factory=list)
    open_area: float = 0.0
    nonmanifold: int = 0
    edges: int = 0
    part_shares: list = field(default_factory=list)

    def lines(self):
        """Short human-readable lines for the CLI and the editor."""
        holes = (f"{len(self.holes)} hole{'s' * (len(self.holes) > 1)}, the largest "
                 f"{100 * self.holes[0]:.1f}% of the size across" if self.holes
                 else "closed (no holes)")
        small = sum(s < SMALL_PART for s in self.part_shares)
        parts = ("one part" if len(self.part_shares) == 1 else
                 f"{len(self.part_shares)} parts, the largest {100 * self.part_shares[0]:.0f}% "
                 f"of the area, {small} small ones (under {100 * SMALL_PART:.0f}%) ride along "
                 "outside the embedding")
        return [f"mesh: {len(self.vertices)} vertices, {len(self.faces)} triangles (welded)",
                f"holes: {holes}", f"non-manifold edges: {self.nonmanifold} of {self.edges}",
                f"parts: {parts}"]


def read_mesh(path, with_surface=False):
    """Vertices and faces of a mesh file to auto-rig: any format :func:`rigedit.io.mesh.load_mesh`
    reads, or a ``.glb``/``.gltf`` (its skinned mesh at the rest pose when it has a skin).

    Parameters
    ----------
    path : str or Path
    with_surface : bool
        Also return the glTF's texture coordinates and materials (a
        :class:`rigedit.surface.Surface` without normals: the file's are in its bind frame;
        None for other formats), so an auto-rigged character keeps its look.

    Returns
    -------
    vertices : (V, 3) float64
    faces : (F, 3) int64
    surface : Surface or None
        Only with ``with_surface``.

    Raises
    ------
    RigFileError
        Unreadable file, or no faces (a point cloud has no inside to embed a skeleton in).
    """
    path = Path(path)
    surface = None
    if path.suffix.lower() in (".glb", ".gltf"):
        from dataclasses import replace

        from ..io.gltf_read import load_gltf

        rig = load_gltf(path)
        faces = rig.faces
        vertices = rig.skin(rig.rest_pose()) if len(rig.vertices) else rig.vertices
        if rig.surface is not None:
            surface = replace(rig.surface, normals=None)
    else:
        from ..io.mesh import load_mesh

        try:
            vertices, faces = load_mesh(path)
        except RigFileError as exc:
            if "no faces" in exc.problem:
                raise RigFileError(path, "expected a surface mesh (triangles or polygons), got "
                                         "no faces: a point cloud has no inside to place a "
                                         "skeleton in") from None
            raise
    if len(faces) == 0:
        raise RigFileError(path, "expected a surface mesh (triangles or polygons), got no "
                                 "faces: a point cloud has no inside to place a skeleton in")
    out = np.asarray(vertices, dtype=np.float64), np.asarray(faces, dtype=np.int64)
    return (*out, surface) if with_surface else out


def _edges(faces):
    """Unique undirected edges (E, 2) and how many triangles use each (E,)."""
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    e.sort(axis=1)
    return np.unique(e, axis=0, return_counts=True)


def _holes(vertices, edges):
    """Perimeter of each loop of boundary edges (connected boundary-edge components)."""
    if len(edges) == 0:
        return np.zeros(0)
    used, inv = np.unique(edges, return_inverse=True)
    inv = inv.reshape(-1, 2)
    g = sp.coo_matrix((np.ones(len(inv)), (inv[:, 0], inv[:, 1])),
                      shape=(len(used), len(used)))
    n, label = connected_components(g, directed=False)
    length = np.linalg.norm(vertices[edges[:, 0]] - vertices[edges[:, 1]], axis=1)
    return np.bincount(label[inv[:, 0]], weights=length, minlength=n)


def check_mesh(vertices, faces, path="mesh"):
    """Check that a mesh can be auto-rigged (see the module notes for what is accepted).

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int
    path : str or Path
        Named in the error.

    Returns
    -------
    MeshCheck

    Raises
    ------
    RigFileError
        One message naming the file and what is wrong.
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if len(faces) == 0:
        raise RigFileError(path, "expected a surface mesh, got no faces: a point cloud has no "
                                 "inside to place a skeleton in")
    diag = max(float(np.linalg.norm(np.ptp(vertices, axis=0))), 1e-12)
    rep, wv = lap.weld(vertices, WELD * diag)
    wf = lap.clean_faces(rep[faces])
    area = lap.face_areas(wv, wf)
    keep = area > 0
    wf, area = wf[keep], area[keep]
    if len(wf) == 0:
        raise RigFileError(path, "expected triangles with an area, got none")
    total = float(area.sum())
    size = float(np.ptp(wv, axis=0).max())
    edges, count = _edges(wf)
    perimeters = np.sort(_holes(wv, edges[count == 1]))[::-1]
    widths = perimeters / np.pi
    holes = list(widths / size)
    open_area = float(np.sum(np.pi / 4 * widths ** 2) / total)
    nonmanifold = int(np.sum(count > 2))
    n, label = lap.components(len(wv), wf)
    part_area = np.bincount(label[wf[:, 0]], weights=area, minlength=n)
    present = part_area > 0
    shares = part_area / total
    order = np.argsort(-shares[present])
    res = MeshCheck(wv, wf, shares[label[wf[:, 0]]] >= SMALL_PART, size, holes, open_area,
                    nonmanifold, len(edges), list(shares[present][order]))
    advice = ("auto-rigging needs a closed mesh or nearly (holes under "
              f"{100 * MAX_HOLE:.0f}% of the size across, together under "
              f"{100 * MAX_OPEN_AREA:.0f}% of the surface)")
    if holes and (holes[0] > MAX_HOLE or open_area > MAX_OPEN_AREA):
        raise RigFileError(path, f"{len(holes)} hole{'s' * (len(holes) > 1)}, the largest "
                                 f"{100 * holes[0]:.0f}% of the mesh's size across, together "
                                 f"{100 * open_area:.0f}% of its surface: {advice}")
    if nonmanifold > MAX_NONMANIFOLD * len(edges):
        raise RigFileError(path, f"{nonmanifold} of {len(edges)} edges are shared by more than "
                                 "two triangles: auto-rigging needs a surface with an inside "
                                 f"(at most {100 * MAX_NONMANIFOLD:.0f}% such edges)")
    if res.part_shares[0] < MIN_MAIN_PART:
        raise RigFileError(path, f"{len(res.part_shares)} separate pieces, the largest only "
                                 f"{100 * res.part_shares[0]:.1f}% of the surface: "
                                 "auto-rigging needs one body (small parts such as eyes may "
                                 "ride along)")
    return res
