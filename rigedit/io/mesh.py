"""Triangle meshes from OBJ (own fast reader), PLY, STL, VTK, VTU (meshio) and VTP."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import RigFileError
from .atomic import atomic_write

__all__ = ["MESH_SUFFIXES", "load_mesh", "save_obj", "weld_vertices", "triangulate"]

MESH_SUFFIXES = (".obj", ".ply", ".stl", ".vtk", ".vtu", ".vtp")


def triangulate(polygons):
    """Fan-triangulate a list of polygons (index lists) into (F, 3) int64."""
    tris = [(p[0], p[i], p[i + 1]) for p in polygons for i in range(1, len(p) - 1)]
    return np.array(tris, dtype=np.int64).reshape(-1, 3)


def weld_vertices(vertices, faces, decimals=9):
    """Merge vertices at the same position (as UV seams split them) and drop faces that the
    merge collapsed.

    Returns
    -------
    vertices : (V', 3) float64
    faces : (F', 3) int64
    """
    key = np.round(vertices, decimals)
    uniq, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    # Keep first-seen order so a welded mesh lists vertices as the file did.
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    new_faces = rank[inverse.reshape(-1)][faces]
    keep = ((new_faces[:, 0] != new_faces[:, 1]) & (new_faces[:, 1] != new_faces[:, 2])
            & (new_faces[:, 0] != new_faces[:, 2]))
    return vertices[first[order]], new_faces[keep]


def _read_obj(path):
    verts, polys = [], []
    with open(path, encoding="utf-8", errors="replace") as fh:
        for lineno, line in enumerate(fh, 1):
            if line.startswith("v "):
                parts = line.split()
                try:
                    verts.append((float(parts[1]), float(parts[2]), float(parts[3])))
                except (IndexError, ValueError):
                    raise RigFileError(path, f"line {lineno}: expected 'v x y z', got "
                                             f"{line.strip()!r}") from None
            elif line.startswith("f "):
                try:
                    # "f v/vt/vn ..." -> position indices; negative indices count from the end
                    idx = [int(tok.split("/")[0]) for tok in line.split()[1:]]
                except ValueError:
                    raise RigFileError(path, f"line {lineno}: expected face indices, got "
                                             f"{line.strip()!r}") from None
                if len(idx) < 3:
                    raise RigFileError(path, f"line {lineno}: a face needs 3 vertices, got "
                                             f"{len(idx)}")
                n = len(verts)
                polys.append([i - 1 if i > 0 else n + i for i in idx])
    vertices = np.array(verts, dtype=np.float64).reshape(-1, 3)
    faces = triangulate(polys)
    return vertices, faces


def _read_meshio(path):
    import meshio  # imported here: only these formats need it

    try:
        m = meshio.read(path)
    except Exception as exc:  # meshio raises many types for a bad file
        raise RigFileError(path, f"cannot read mesh: {exc}") from None
    polys = []
    for block in m.cells:
        if block.type == "triangle":
            polys.extend(block.data.tolist())
        elif block.type in ("quad", "polygon"):
            polys.extend(block.data.tolist())
    return np.asarray(m.points, dtype=np.float64)[:, :3], triangulate(polys)


def _read_vtp(path):
    # VTP (XML PolyData) is not among meshio's formats; pyvista reads it. This is the one
    # place below rigedit/render that touches pyvista, and only when a VTP file is opened.
    import pyvista as pv

    try:
        poly = pv.read(path).extract_surface().triangulate()
    except Exception as exc:
        raise RigFileError(path, f"cannot read mesh: {exc}") from None
    return np.asarray(poly.points, dtype=np.float64), poly.faces.reshape(-1, 4)[:, 1:].astype(
        np.int64)


def load_mesh(path, weld=True):
    """Read a triangle mesh.

    Parameters
    ----------
    path : str or Path
    weld : bool
        Merge vertices that share a position (OBJ files split them at UV seams).

    Returns
    -------
    vertices : (V, 3) float64
    faces : (F, 3) int64

    Raises
    ------
    RigFileError
        Missing file, unknown format, malformed content, no triangles, indices out of range.
    """
    path = Path(path)
    if not path.is_file():
        raise RigFileError(path, "file not found")
    suffix = path.suffix.lower()
    if suffix == ".obj":
        vertices, faces = _read_obj(path)
    elif suffix == ".vtp":
        vertices, faces = _read_vtp(path)
    elif suffix in MESH_SUFFIXES:
        vertices, faces = _read_meshio(path)
    else:
        raise RigFileError(path, f"expected a mesh file ({', '.join(MESH_SUFFIXES)}), got "
                                 f"{suffix or 'no extension'}")
    if len(faces) == 0:
        raise RigFileError(path, "expected triangles or polygons, got no faces")
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise RigFileError(path, f"face index out of range: {len(vertices)} vertices, index "
                                 f"{int(faces.max()) + 1 if faces.max() >= len(vertices) else int(faces.min()) + 1}")
    if not np.all(np.isfinite(vertices)):
        raise RigFileError(path, "expected finite vertex coordinates, got NaN or inf")
    if weld:
        vertices, faces = weld_vertices(vertices, faces)
    # Keep only referenced vertices: stray points would get weights and bounding boxes wrong.
    used = np.zeros(len(vertices), dtype=bool)
    used[faces.ravel()] = True
    if not used.all():
        remap = np.cumsum(used) - 1
        vertices, faces = vertices[used], remap[faces]
    return vertices, faces


def save_obj(path, vertices, faces, header=None):
    """Write a triangle mesh as OBJ, atomically."""
    with atomic_write(path) as fh:
        if header:
            fh.write(f"# {header}\n")
        np.savetxt(fh, vertices, fmt="v %.6f %.6f %.6f")
        np.savetxt(fh, np.asarray(faces) + 1, fmt="f %d %d %d")
