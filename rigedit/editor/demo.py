"""A small rig built in code: the editor's fallback when no bundled character is installed, and
the UI tests' fixture. A four-legged creature of tubes around its bones, Y up, facing +Z."""
from __future__ import annotations

import numpy as np

from ..io.mesh import weld_vertices
from ..io.skeleton_json import skeleton_from_heads
from ..rig import Rig
from .files import load_rig

__all__ = ["default_rig", "demo_rig"]

_JOINTS = [  # name, parent, head (x, y, z)
    ("root", None, (0.0, 0.0, 0.0)),
    ("hips", "root", (0.0, 1.0, -0.6)),
    ("spine", "hips", (0.0, 1.05, 0.0)),
    ("chest", "spine", (0.0, 1.1, 0.6)),
    ("neck", "chest", (0.0, 1.45, 0.85)),
    ("head", "neck", (0.0, 1.7, 1.0)),
    ("tail", "hips", (0.0, 1.05, -1.0)),
]
for _side, _x in (("L", 0.3), ("R", -0.3)):
    for _part, _top, _z in (("front", "chest", 0.6), ("back", "hips", -0.6)):
        _JOINTS += [
            (f"{_part}_thigh_{_side}", _top, (_x, 0.95, _z)),
            (f"{_part}_shin_{_side}", f"{_part}_thigh_{_side}", (_x, 0.5, _z + 0.05)),
            (f"{_part}_foot_{_side}", f"{_part}_shin_{_side}", (_x, 0.08, _z)),
        ]
_TAILS = {"head": (0.0, 1.75, 1.35), "tail": (0.0, 0.9, -1.5)}
for _side, _x in (("L", 0.3), ("R", -0.3)):
    for _part, _z in (("front", 0.6), ("back", -0.6)):
        _TAILS[f"{_part}_foot_{_side}"] = (_x, 0.0, _z + 0.2)


def _tube(a, b, radius, sides=12, rings=6):
    """Vertices and faces of an open tube from ``a`` to ``b`` with capped ends."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    axis = b - a
    length = np.linalg.norm(axis)
    d = axis / length
    u = np.cross(d, [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(d, u)
    ang = np.linspace(0, 2 * np.pi, sides, endpoint=False)
    circle = np.cos(ang)[:, None] * u + np.sin(ang)[:, None] * v
    t = np.linspace(0.0, 1.0, rings)
    # Slight bulge in the middle so it reads as a limb, not a pipe.
    r = radius * (0.85 + 0.3 * np.sin(np.pi * t))
    verts = (a + t[:, None, None] * axis) + r[:, None, None] * circle[None]
    verts = verts.reshape(-1, 3)
    faces = []
    for i in range(rings - 1):
        for k in range(sides):
            p, q = i * sides + k, i * sides + (k + 1) % sides
            faces += [(p, q, q + sides), (p, q + sides, p + sides)]
    start, end = len(verts), len(verts) + 1
    verts = np.vstack([verts, a - d * radius * 0.5, b + d * radius * 0.5])
    for k in range(sides):
        faces.append((start, (k + 1) % sides, k))
        off = (rings - 1) * sides
        faces.append((end, off + k, off + (k + 1) % sides))
    return verts, np.array(faces)


def demo_rig():
    """A 19-joint quadruped of tubes (about 2.5k vertices), weights by inverse distance.

    Returns
    -------
    Rig
    """
    names = [j[0] for j in _JOINTS]
    parents = [j[1] for j in _JOINTS]
    heads = np.array([j[2] for j in _JOINTS])
    tails = np.array([_TAILS.get(n, (np.nan,) * 3) for n in names])
    deform = np.array([n != "root" for n in names])
    skeleton = skeleton_from_heads(names, parents, heads, tails, deform)
    hb = skeleton.bind_matrices[:, :3, 3]
    verts, faces = [], []
    offset = 0
    for j, name in enumerate(skeleton.names):
        if not skeleton.deform[j]:
            continue
        kids = [k for k in skeleton.children(j)]
        ends = [skeleton.tails[j]] if np.all(np.isfinite(skeleton.tails[j])) else [hb[k] for k in kids]
        if name in ("hips", "chest"):  # the body: one fat tube per torso bone only
            ends = [hb[k] for k in kids if skeleton.names[k] in ("spine", "neck")]
        for end in ends:
            radius = 0.28 if name in ("hips", "spine", "chest") else 0.09
            if name == "head":
                radius = 0.16
            v, f = _tube(hb[j], end, radius, sides=16, rings=10)
            verts.append(v)
            faces.append(f + offset)
            offset += len(v)
    # Tubes meet at joints: merge coincident vertices, as the mesh loader would on reading.
    vertices, faces = weld_vertices(np.vstack(verts), np.vstack(faces))
    return Rig(skeleton, vertices, faces, name="demo creature", up="y")


def default_rig():
    """The bundled quadruped, or the code-built creature when the assets are not installed.

    Returns
    -------
    rig : Rig
    note : str or None
        Why the fallback was used.
    """
    try:
        return load_rig(quiet=True), None
    except (ValueError, OSError) as exc:
        return demo_rig(), f"bundled quadruped not available ({exc}); showing a demo creature"
