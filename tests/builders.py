"""Small rigs built in code, for exact answers in tests (numpy only)."""
from __future__ import annotations

import json

import numpy as np

from rigedit.animation import Clip, Track
from rigedit.model import Skeleton
from rigedit.model.transforms import euler_to_quat
from rigedit.rig import Rig


def chain_skeleton(n=3, length=1.0):
    """A chain of ``n`` joints along +Y, ``length`` apart."""
    names = [f"j{i}" for i in range(n)]
    t = np.zeros((n, 3))
    t[1:, 1] = length
    tails = np.full((n, 3), np.nan)
    tails[-1] = [0.0, n * length, 0.0]
    return Skeleton(names, np.arange(n) - 1, t, tails=tails)


def cylinder(radius=0.3, height=3.0, rings=31, segments=24):
    """A closed triangulated cylinder along +Y from y=0 to y=height.

    Returns
    -------
    vertices : (V, 3), faces : (F, 3)
    """
    ang = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    ys = np.linspace(0, height, rings)
    ring = np.stack([radius * np.cos(ang), np.zeros(segments), -radius * np.sin(ang)], 1)
    verts = [ring + [0, y, 0] for y in ys]
    verts = np.concatenate(verts + [[[0, 0, 0]], [[0, height, 0]]])
    faces = []
    for r in range(rings - 1):
        for s in range(segments):
            a, b = r * segments + s, r * segments + (s + 1) % segments
            c, d = a + segments, b + segments
            faces += [(a, b, d), (a, d, c)]
    bottom, top = rings * segments, rings * segments + 1
    last = (rings - 1) * segments
    for s in range(segments):
        faces.append((bottom, (s + 1) % segments, s))
        faces.append((top, last + s, last + (s + 1) % segments))
    return verts.astype(float), np.array(faces)


def cylinder_rig(with_clip=True):
    """A cylinder of height 3 bound by inverse distance to a 3-joint chain along +Y."""
    sk = chain_skeleton(3)
    v, f = cylinder()
    clips = {}
    if with_clip:
        q = euler_to_quat([[0, 0, 0], [0, 0, 60], [0, 0, 0]], degrees=True)
        clips["bend"] = Clip("bend", sk, {("j1", "rotation"): Track("rotation", [0, .5, 1], q)})
    return Rig(sk, v, f, clips=clips, name="cylinder")


def write_elk_folder(folder, extra_clip_joints=()):
    """Write a rig folder in the elk project's layout (Z up) and return its path.

    A zero-length ``_rootJoint`` at the origin, a 3-bone chain up +Z, the mesh in
    ``models/body.obj`` with UV seams (duplicated positions), normals and a material.
    """
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "models").mkdir(exist_ok=True)
    (folder / "skeleton").mkdir(exist_ok=True)
    (folder / "animations").mkdir(exist_ok=True)
    joints = [
        {"name": "_rootJoint", "index": 0, "head": [0, 0, 0], "tail": [0, 0, 0], "parent": None},
        {"name": "hip", "index": 1, "head": [0, 0, 0.5], "tail": [0, 0, 1.5], "parent": "_rootJoint"},
        {"name": "spine", "index": 2, "head": [0, 0, 1.5], "tail": [0, 0, 2.5], "parent": "hip"},
        {"name": "head", "index": 3, "head": [0, 0, 2.5], "tail": [0, 0, 3.5], "parent": "spine"},
    ]
    (folder / "skeleton" / "skeleton.json").write_text(json.dumps({
        "joints": joints, "bones": [j["name"] for j in joints[1:]],
        "hierarchy": {j["name"]: j["parent"] for j in joints[1:]}}))
    v, f = cylinder(height=3.0)
    v = v[:, [0, 2, 1]] * [1, -1, 1] + [0, 0, 0.5]   # along +Z from z=0.5, same orientation
    lines = ["mtllib body.mtl", "o body"]
    lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in v]
    # Duplicate the first 10 positions as seam vertices and use them in some faces.
    lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in v[:10]]
    lines += ["vt 0 0", "vn 0 0 1", "usemtl skin", "s 1"]
    n = len(v)
    for a, b, c in f:
        ids = [i + n + 1 if i < 10 and a % 2 else i + 1 for i in (a, b, c)]
        lines.append("f " + " ".join(f"{i}/1/1" for i in ids))
    (folder / "models" / "body.obj").write_text("\n".join(lines) + "\n")
    keys = {"spine": [{"time": 0.0, "rotation": [0, 0, 0], "translation": [0, 0, 0],
                       "scale": [1, 1, 1]},
                      {"time": 1.0, "rotation": [0.5, 0, 0], "translation": [0, 0, 0],
                       "scale": [1, 1, 1]}]}
    for name in extra_clip_joints:
        keys[name] = [{"time": 0.0, "rotation": [0, 0, 0]}]
    (folder / "animations" / "bow.json").write_text(json.dumps(
        {"name": "bow", "duration": 1.0, "keyframes": keys}))
    return folder
