"""Triangle meshes from OBJ (own fast reader), PLY, STL, VTK, VTU (meshio) and VTP."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import RigFileError
from .atomic import atomic_write
from .jsonfile import MAX_MAGNITUDE
from .mesh_common import third_party_read, triangulate
from .paths import read_bytes, regular_file
from .vtp import read_vtp

__all__ = ["MESH_SUFFIXES", "load_mesh", "save_obj", "weld_vertices", "triangulate",
           "third_party_read"]

MESH_SUFFIXES = (".obj", ".ply", ".stl", ".vtk", ".vtu", ".vtp")


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


#: Largest vertex index a face may use (int32, as every mesh format and VTK store them).
MAX_INDEX = 2**31 - 1


def _obj_face(path, lineno, tokens, n):
    """0-based vertex indices of an OBJ face line (``f v/vt/vn ...``); negative indices count
    back from the last vertex read so far."""
    try:
        idx = [int(tok.split("/")[0]) for tok in tokens]
    except ValueError:
        raise RigFileError(path, f"line {lineno}: expected face indices, got "
                                 f"{' '.join(tokens)[:60]!r}") from None
    if len(idx) < 3:
        raise RigFileError(path, f"line {lineno}: a face needs 3 vertices, got "
                                 f"{len(idx)}")
    out = []
    for i in idx:
        if i == 0:
            raise RigFileError(path, f"line {lineno}: face index 0 (OBJ indices start at 1, "
                                     "or count back from -1)")
        if abs(i) > MAX_INDEX:
            raise RigFileError(path, f"line {lineno}: expected face indices up to {MAX_INDEX},"
                                     f" got {str(i)[:30]}")
        out.append(i - 1 if i > 0 else n + i)
    return out


def _read_obj(path):
    raw = read_bytes(path)
    if b"\0" in raw[:65536]:
        raise RigFileError(path, "expected a text OBJ file, got binary data")
    verts, polys = [], []
    # utf-8-sig: a byte-order mark at the start is not part of the first line.
    for lineno, line in enumerate(raw.decode("utf-8-sig", errors="replace").splitlines(), 1):
        tokens = line.split()  # any whitespace: tabs and leading spaces are valid OBJ
        if not tokens:
            continue
        if tokens[0] == "v":
            try:
                verts.append((float(tokens[1]), float(tokens[2]), float(tokens[3])))
            except (IndexError, ValueError):
                raise RigFileError(path, f"line {lineno}: expected 'v x y z', got "
                                         f"{line.strip()[:60]!r}") from None
        elif tokens[0] == "f":
            polys.append(_obj_face(path, lineno, tokens[1:], len(verts)))
    vertices = np.array(verts, dtype=np.float64).reshape(-1, 3)
    faces = triangulate(polys)
    return vertices, faces


def _check_ply_header(path, size):
    """meshio's PLY reader loops for ever on a header without ``end_header`` and trusts the
    element counts: check both before it runs."""
    with open(path, "rb") as fh:
        head = fh.read(65536)
    end = head.find(b"end_header")
    if not head.startswith(b"ply") or end < 0:
        raise RigFileError(path, "expected a PLY header ('ply' ... 'end_header') in the first "
                                 "64 KiB, got none")
    for line in head[:end].decode("ascii", "replace").splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[0] == "element":
            if not parts[2].isdigit() or int(parts[2]) > size:
                raise RigFileError(path, f"expected an element count the file can hold, got "
                                         f"{line.strip()[:60]!r} in a file of {size} bytes")


def _read_meshio(path):
    import meshio  # imported here: only these formats need it

    if path.suffix.lower() == ".ply":
        _check_ply_header(path, path.stat().st_size)

    m = third_party_read(path, lambda: meshio.read(path))
    polys, in_range = [], True
    for block in m.cells:
        if block.type in ("triangle", "quad", "polygon"):
            data = np.asarray(block.data)
            if data.dtype.kind not in "iu":
                raise RigFileError(path, f"expected integer face indices, got {data.dtype}")
            in_range &= not data.size or (data.min() >= 0 and data.max() <= MAX_INDEX)
            polys.extend(data.tolist())
    points = np.asarray(m.points)
    if points.ndim != 2 or points.shape[1] < 3 or points.dtype.kind not in "iuf":
        raise RigFileError(path, f"expected 3D points, got an array of shape {points.shape}")
    if not in_range:
        raise RigFileError(path, f"expected face indices from 0 to {MAX_INDEX}")
    return points[:, :3].astype(np.float64), triangulate(polys)


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
    regular_file(path)
    suffix = path.suffix.lower()
    if suffix == ".obj":
        vertices, faces = _read_obj(path)
    elif suffix == ".vtp":
        vertices, faces = read_vtp(path)
    elif suffix in MESH_SUFFIXES:
        vertices, faces = _read_meshio(path)
    else:
        raise RigFileError(path, f"expected a mesh file ({', '.join(MESH_SUFFIXES)}), got "
                                 f"{suffix or 'no extension'}")
    if len(faces) == 0:
        raise RigFileError(path, "expected triangles or polygons, got no faces")
    if faces.min() < 0 or faces.max() >= len(vertices):
        bad = int(faces.max()) if faces.max() >= len(vertices) else int(faces.min())
        raise RigFileError(path, f"face index out of range: {len(vertices)} vertices, index "
                                 f"{bad + 1} (1-based)")
    if not np.all(np.isfinite(vertices)):
        raise RigFileError(path, "expected finite vertex coordinates, got NaN or inf")
    if np.abs(vertices).max() > MAX_MAGNITUDE:
        raise RigFileError(path, f"expected vertex coordinates within +-{MAX_MAGNITUDE:g}, got "
                                 f"{np.abs(vertices).max():g}")
    _check_area(path, vertices, faces)
    if weld:
        vertices, faces = weld_vertices(vertices, faces)
    # Keep only referenced vertices: stray points would get weights and bounding boxes wrong.
    used = np.zeros(len(vertices), dtype=bool)
    used[faces.ravel()] = True
    if not used.all():
        remap = np.cumsum(used) - 1
        vertices, faces = vertices[used], remap[faces]
    return vertices, faces


def _check_area(path, vertices, faces):
    """An error when every face is degenerate (a repeated vertex or no area): such a mesh has
    no surface to show or to skin. Some degenerate faces among good ones are kept as read."""
    tri = vertices[faces]
    area2 = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    keep = ((faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2])
            & (faces[:, 0] != faces[:, 2]) & (area2 > 0))
    if not keep.any():
        raise RigFileError(path, f"expected faces with an area, got none among {len(faces)} "
                                 "(each repeats a vertex or has its corners on a line)")


def save_obj(path, vertices, faces, header=None):
    """Write a triangle mesh as OBJ, atomically."""
    with atomic_write(path) as fh:
        if header:
            fh.write(f"# {header}\n")
        np.savetxt(fh, vertices, fmt="v %.6f %.6f %.6f")
        np.savetxt(fh, np.asarray(faces) + 1, fmt="f %d %d %d")
