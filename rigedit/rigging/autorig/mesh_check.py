"""Read and check a mesh to be auto-rigged, and give the embedding a volume it can use.

The embedding needs an inside and an outside (a distance field, medial spheres). After
welding coincident vertices (glTF and OBJ split them at UV seams), a mesh is embedded as it
is (the fast path, unchanged for closed meshes) when:

- it is closed or nearly so: every hole (a loop of boundary edges) is at most
  :data:`MAX_HOLE` (10%) of the mesh's size across (its largest bounding-box side; a hole's
  width is its perimeter / pi, a circle's diameter), and the holes together would be covered
  by discs of at most :data:`MAX_OPEN_AREA` (5%) of the surface area (ray parity votes
  past such holes);
- no edge is shared by more than two triangles (interior faces break ray parity);
- one part holds the body: parts under :data:`SMALL_PART` (1%) of the area (eyes, teeth,
  buttons) ride along outside the embedding (they get skin weights like the rest);
- a surface without holes does not run through itself: along grid lines, at most
  :data:`MAX_TWICE` (0.5%) of its inside is enclosed twice (the winding number, for a
  consistently facing surface; parity calls such places outside).

Any other mesh (open, non-manifold, self-intersecting, several parts that may overlap or
nest, interior faces, triangle soup) is embedded in a watertight proxy of its volume
(:func:`rigedit.embedding.volume.volume_proxy`), built from all its parts; the skin weights
stay on the real mesh. ``MeshCheck.proxy_reason`` says why, and the report says so in one
line. Refused, naming the file: no faces (a point cloud), no triangle with an area, no
volume even with holes closed (a flat or open sheet), or a proxy whose largest piece holds
under :data:`MIN_MAIN_PART` (10%) of the volume (a scatter of pieces, not a character).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ...embedding.volume import NoVolumeError, volume_proxy
from ...errors import RigFileError
from ...binding import laplacian as lap
from ...binding.heat import WELD  # welded as the heat weights weld it

__all__ = ["MeshCheck", "read_mesh", "check_mesh", "MAX_HOLE", "MAX_OPEN_AREA",
           "MIN_MAIN_PART", "SMALL_PART", "MAX_TWICE"]

MAX_HOLE = 0.10
MAX_OPEN_AREA = 0.05
MIN_MAIN_PART = 0.10
SMALL_PART = 0.01
#: A closed mesh that encloses more than this share of its inside twice (it runs through
#: itself) goes through the proxy; a fingertip grazing a thigh does not matter.
MAX_TWICE = 0.005


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
    proxy : VolumeProxy or None
        The watertight proxy the embedding uses instead of the mesh, when one is needed.
    proxy_reason : str
        Why the proxy was needed ("" without one).
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
    proxy: object = None
    proxy_reason: str = ""

    def embedding_mesh(self):
        """(vertices (P, 3), faces (Q, 3)) to embed: the proxy's, else the body parts'."""
        if self.proxy is not None:
            return self.proxy.vertices, self.proxy.faces
        return self.vertices, self.faces[self.body]

    def lines(self):
        """Short human-readable lines for the CLI and the editor."""
        holes = (f"{len(self.holes)} hole{'s' * (len(self.holes) > 1)}, the largest "
                 f"{100 * self.holes[0]:.1f}% of the size across" if self.holes
                 else "closed (no holes)")
        small = sum(s < SMALL_PART for s in self.part_shares)
        parts = ("one part" if len(self.part_shares) == 1 else
                 f"{len(self.part_shares)} parts, the largest {100 * self.part_shares[0]:.0f}% "
                 f"of the area, " + ("all in the proxy" if self.proxy is not None else
                                     f"{small} small ones (under {100 * SMALL_PART:.0f}%) "
                                     "ride along outside the embedding"))
        out = [f"mesh: {len(self.vertices)} vertices, {len(self.faces)} triangles (welded)",
               f"holes: {holes}", f"non-manifold edges: {self.nonmanifold} of {self.edges}",
               f"parts: {parts}"]
        if self.proxy is not None:
            p = self.proxy
            out.append(f"proxy: {self.proxy_reason}; embedded in a watertight proxy of "
                       f"{len(p.faces) / 1000:.0f}k triangles (cells of {p.h:.3g}, "
                       f"{p.seconds:.1f} s)")
        return out


def _read_gltf(path):
    """(vertices, faces, surface or None) of a glTF to auto-rig.

    A file whose meshes are all bound to one skin is read as the editor reads it (skinned at
    its rest pose, with its look). Otherwise (no skin: a static asset; or parts that hang
    from nodes or from a second skin, as RobotExpressive's body parts hang from its bones
    and only its hands are skinned) every triangle primitive of every mesh node is placed
    where the file puts it: a skinned one by its skin at the nodes' default pose (the node's
    own transform ignored, as the spec says), any other by its node's world matrix. Morph
    targets are left out (the base shape).
    """
    from dataclasses import replace

    from ...io.gltf_data import GltfData
    from ...io.gltf_read import read_gltf
    from ...rig import Rig

    data = GltfData(path)
    nodes = data.gltf.nodes or []
    meshed = [i for i, n in enumerate(nodes) if n.mesh is not None]
    skins = {nodes[i].skin for i in meshed}
    if meshed and len(skins) == 1 and None not in skins:
        rig = Rig.from_data(read_gltf(path))
        vertices = rig.skin(rig.rest_pose()) if len(rig.vertices) else rig.vertices
        surface = replace(rig.surface, normals=None) if rig.surface is not None else None
        return np.asarray(vertices, dtype=np.float64), rig.faces, surface
    try:
        return _gltf_meshes(data, meshed)
    except (TypeError, ValueError, KeyError, IndexError, AttributeError) as exc:
        raise RigFileError(path, f"expected valid glTF meshes, got a malformed field "
                                 f"({type(exc).__name__}: {exc})") from None


def _gltf_meshes(data, meshed):
    """Every triangle primitive of the nodes ``meshed``, placed (see :func:`_read_gltf`)."""
    from ...io.gltf_mesh import TRIANGLES, triangles
    from ...io.gltf_read import _local_matrix, _node_parents

    nodes = data.gltf.nodes
    parent = _node_parents(data)
    world = [None] * len(nodes)

    def world_of(i):
        if world[i] is None:
            local = _local_matrix(data, i)
            world[i] = local if parent[i] < 0 else world_of(parent[i]) @ local
        return world[i]

    verts, faces, offset = [], [], 0
    for i in meshed:
        node = nodes[i]
        skin = data.gltf.skins[node.skin] if node.skin is not None else None
        palette = None
        if skin is not None:
            ibm = (data.accessor(skin.inverseBindMatrices).reshape(-1, 4, 4).transpose(0, 2, 1)
                   if skin.inverseBindMatrices is not None
                   else np.tile(np.eye(4), (len(skin.joints), 1, 1)))
            palette = np.array([world_of(j) for j in skin.joints]) @ ibm
        for prim in data.gltf.meshes[node.mesh].primitives or []:
            mode = TRIANGLES if prim.mode is None else prim.mode
            if mode not in (4, 5, 6) or prim.attributes.POSITION is None:
                continue
            pos = data.accessor(prim.attributes.POSITION)[:, :3]
            idx = (np.arange(len(pos)) if prim.indices is None else
                   data.accessor(prim.indices)[:, 0].astype(np.int64))
            h = np.c_[pos, np.ones(len(pos))]
            if palette is None:
                placed = h @ world_of(i).T
            else:
                j = data.accessor(prim.attributes.JOINTS_0).astype(np.int64)
                w = data.accessor(prim.attributes.WEIGHTS_0)
                w = w / np.maximum(w.sum(axis=1, keepdims=True), 1e-12)
                blend = np.einsum("vk,vkij->vij", w, palette[np.clip(j, 0, len(palette) - 1)])
                placed = np.einsum("vij,vj->vi", blend, h)
            if not np.all(np.isfinite(placed)):
                raise RigFileError(data.path, f"mesh {node.mesh}: expected finite vertex "
                                              "positions once placed, got NaN or inf")
            if idx.size and (idx.min() < 0 or idx.max() >= len(pos)):
                raise RigFileError(data.path, f"mesh {node.mesh}: expected indices below "
                                              f"{len(pos)} vertices, got {idx.max()}")
            verts.append(placed[:, :3])
            faces.append(triangles(idx, mode) + offset)
            offset += len(pos)
    if not verts:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), None
    return np.concatenate(verts), np.concatenate(faces), None


def read_mesh(path, with_surface=False):
    """Vertices and faces of a mesh file to auto-rig: any format :func:`rigedit.io.mesh.load_mesh`
    reads, or a ``.glb``/``.gltf``: its skinned mesh at the rest pose when that is all its
    geometry, else every mesh of the file where the file places it (see :func:`_read_gltf`).

    Parameters
    ----------
    path : str or Path
    with_surface : bool
        Also return the glTF's texture coordinates and materials (a
        :class:`rigedit.surface.Surface` without normals: the file's are in its bind frame;
        None for other formats and for a glTF read mesh by mesh), so an auto-rigged
        character keeps its look.

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
        vertices, faces, surface = _read_gltf(path)
    else:
        from ...io.mesh import load_mesh

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
    vertices, faces = np.asarray(vertices, dtype=np.float64), np.asarray(faces, dtype=np.int64)
    if surface is None:
        # drop points no triangle uses (a glTF's meshes may carry some), as load_mesh does:
        # a rig folder saved from this mesh is read back without them, and its weights.npz
        # must then still fit (RobotExpressive has 4: its folder did not load)
        used = np.zeros(len(vertices), dtype=bool)
        used[faces.ravel()] = True
        if not used.all():
            vertices, faces = vertices[used], (np.cumsum(used) - 1)[faces]
    return (vertices, faces, surface) if with_surface else (vertices, faces)


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


def _runs_through_itself(vertices, faces):
    """Share of the inside that a closed, consistently facing surface encloses twice or
    more (the winding number along grid lines): parity calls such places outside. 0.0 when
    the facing is not consistent (the winding then says nothing)."""
    from ...embedding.distance import line_winding

    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    if len(np.unique(directed, axis=0)) < len(directed):
        return 0.0
    w = line_winding(vertices, faces, axis=1)
    if np.sum(w < 0) > np.sum(w > 0):       # facing in throughout: the same, mirrored
        w = -w
    inside = np.sum(w > 0)
    return float(np.sum(w >= 2) / inside) if inside else 0.0


def _proxy_reasons(holes, open_area, nonmanifold, edges, part_shares):
    """Why ray parity on the mesh itself cannot be trusted: one phrase per cause."""
    out = []
    if holes and (holes[0] > MAX_HOLE or open_area > MAX_OPEN_AREA):
        out.append(f"open mesh: {len(holes)} hole{'s' * (len(holes) > 1)}, the largest "
                   f"{100 * holes[0]:.0f}% of its size across, together "
                   f"{100 * open_area:.0f}% of its surface")
    if nonmanifold:
        out.append(f"{nonmanifold} of {edges} edges shared by more than two triangles "
                   "(interior faces, touching parts or a soup)")
    body = sum(s >= SMALL_PART for s in part_shares)
    if body > 1:
        out.append(f"{body} separate parts over {100 * SMALL_PART:.0f}% of the area each "
                   "(overlapping or nested parts have no single inside)")
    return out


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
        One message naming the file and what is wrong: no faces, no volume, a scatter of
        pieces.
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
    reasons = _proxy_reasons(holes, open_area, nonmanifold, len(edges), res.part_shares)
    if not reasons and not holes:
        twice = _runs_through_itself(wv, wf)
        if twice > MAX_TWICE:
            reasons.append(f"self-intersecting: {100 * twice:.1f}% of its inside is enclosed "
                           "twice (ray parity would call it outside)")
    if not reasons:
        return res                  # the fast path: the mesh itself is embedded
    try:
        res.proxy = volume_proxy(wv, wf)
    except NoVolumeError as exc:
        raise RigFileError(path, f"no volume to place a skeleton in: {exc} "
                                 f"({'; '.join(reasons)})") from None
    res.proxy_reason = "; ".join(reasons)
    if res.proxy.largest < MIN_MAIN_PART:
        raise RigFileError(path, f"the volume falls into {res.proxy.pieces} separate pieces, "
                                 f"the largest only "
                                 f"{100 * res.proxy.largest:.1f}% of it: auto-rigging needs "
                                 "one body (small parts such as eyes may ride along)")
    return res
