"""Automatic weights against an artist's, measured by the deformation they give.

For every character in ``../shared/data`` with artist weights and a clip, and the bundled
characters: compute automatic weights from the mesh and skeleton alone, skin every integer
frame at 24 fps of one clip (``walk``, else ``run``, else the first) with the artist's weights
(P_a) and with the automatic ones (P_b), same joint and inverse bind matrices, 4
influences. The error of a vertex at a frame is |P_a - P_b| in the rig's model space (the
world, but for a glTF ancestor node the loader keeps as a joint: RobotExpressive's Armature
node scales it by 100), given as a percentage of the diagonal of the mesh's bounding box at
the rest pose in the same space, so every figure is scale-free; the diagonal is printed, so
a figure times ``diag / 100`` is the error in world units. Prints mean, p95 and max over
vertices and frames, the mean L1 distance between weight rows, and how many vertices needed
a fallback (heat) or were left unweighted (Blender).

Blender's row is measured from ``benchmarks/blender_bone_heat.py``'s output (run by hand,
Blender 3.4.1): its vertices are matched to the rig's by nearest neighbour in the glTF's
mesh coordinates, its bones by name; a vertex Blender left unweighted stays at rest (in
Blender it would follow the armature object only).

    blender -b --python benchmarks/blender_bone_heat.py -- /tmp/blender_heat FILE ...
    .venv/bin/python benchmarks/bench_weights_quality.py [--blender /tmp/blender_heat]
        [--variants] [--only NAME]

``--variants`` also measures the choices heat makes (visibility rule, tails, helper joints,
ranking), for the record in the README.
"""
from __future__ import annotations

import argparse
import time
import warnings
from itertools import permutations
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from rigedit.io import gltf_read
from rigedit.io.load import load_rig
from rigedit.model.skinning import dense_weights, top_k_influences
from rigedit.binding.weights import compute_weights

DATA = Path(__file__).resolve().parents[1] / ".." / "shared" / "data"
# (label, file under DATA or a bundled name, skin index)
CHARACTERS = [
    ("RiggedFigure", "khronos-gltf/RiggedFigure.glb", 0),
    ("CesiumMan", "khronos-gltf/CesiumMan.glb", 0),
    ("RiggedSimple", "khronos-gltf/RiggedSimple.glb", 0),
    ("Xbot", "threejs-characters/Xbot.glb", 0),
    ("RobotExpressive.R", "threejs-characters/RobotExpressive.glb", 0),
    ("RobotExpressive.L", "threejs-characters/RobotExpressive.glb", 1),
    ("Horse", "quaternius-farm-animals/Horse.gltf", 0),
    ("humanoid", "humanoid", 0),
    ("quadruped", "quadruped", 0),
]
FPS = 24
CLIP_PREFERENCE = ("walk", "run")


def load(spec, skin):
    """The rig of a character; glTF files with several skins load skin ``skin``."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if not spec.endswith((".glb", ".gltf")):
            return load_rig(spec)
        choose = gltf_read._choose_skin
        if skin:
            def pick(data):  # the loader takes the first skin with a mesh; take another
                g = data.gltf
                bound = [i for i, n in enumerate(g.nodes) if n.skin == skin and n.mesh is not None]
                return skin, bound
            gltf_read._choose_skin = pick
        try:
            return gltf_read.load_gltf(DATA / spec)
        finally:
            gltf_read._choose_skin = choose


def pick_clip(rig):
    names = list(rig.clips)
    for want in CLIP_PREFERENCE:
        for n in names:
            if n.lower() == want:
                return n
    return names[0]


def skin(vertices, indices, weights, palette):
    """(V, 3) linear blend skinning, the reference formula; rows of zero weight stay put."""
    blended = np.einsum("vk,vkij->vij", weights, palette[indices])
    out = np.einsum("vij,vj->vi", blended[:, :3, :3], vertices) + blended[:, :3, 3]
    still = weights.sum(axis=1) <= 0
    out[still] = vertices[still]
    return out


def palettes(rig, clip):
    """Skinning palettes (J, 4, 4) of every integer frame at FPS of ``clip``."""
    clip = rig.clips[clip]
    n = int(np.floor(clip.duration * FPS + 1e-9)) + 1
    for i in range(n):
        yield rig.joint_matrices(clip.sample(i / FPS)) @ rig.skeleton.inverse_bind_matrices


def measure(rig, clip, dense_auto):
    """Error statistics (% of the rest diagonal) and mean L1 row distance to the artist."""
    j = len(rig.skeleton)
    lo, hi = rig.bounds()
    diag = float(np.linalg.norm(hi - lo))
    ai, aw = top_k_influences(dense_weights(rig.binding.indices, rig.binding.weights, j), 4)
    bi, bw = top_k_influences(dense_auto, 4)
    errs = []
    for palette in palettes(rig, clip):
        errs.append(np.linalg.norm(skin(rig.vertices, ai, aw, palette)
                                   - skin(rig.vertices, bi, bw, palette), axis=1))
    e = 100.0 * np.concatenate(errs) / diag
    l1 = np.abs(dense_weights(ai, aw, j) - dense_weights(bi, bw, j)).sum(axis=1).mean()
    return e.mean(), np.percentile(e, 95), e.max(), l1, diag


def run(method, rig, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t = time.perf_counter()
        res = compute_weights(rig.vertices, rig.skeleton, method, max_influences=4,
                              faces=rig.faces, **options)
        dt = time.perf_counter() - t
    fallback = len(getattr(res, "fallback", ()))
    return dense_weights(res[0], res[1], len(rig.skeleton)), fallback, dt


def blender_weights(rig, path):
    """Blender's weights mapped onto the rig's vertices and joints, or None; unweighted."""
    if not path.exists():
        return None
    data = np.load(path)
    # Blender keeps each mesh node an object (the loader merges those bound to one skin)
    # and each in its node's frame: match the vertices in order, up to one similarity.
    near = _match(rig.vertices, [data[f"v{i}"] for i in range(len(data["objects"]))])
    if near is None:
        print("  (Blender's vertices do not match the rig's)")
        return None
    objs = range(len(data["objects"]))
    col = {n: c for c, n in enumerate(rig.skeleton.names)}
    w = np.zeros((len(rig.vertices), len(rig.skeleton)))
    src = np.concatenate([data[f"w{i}"] for i in objs])[near]
    missing = []
    for b, name in enumerate(data["bones"]):
        if name in col:
            w[:, col[name]] += src[:, b]
        elif src[:, b].any():
            missing.append(name)
    if missing:
        print(f"  (Blender bones not in the rig: {', '.join(missing[:5])})")
    s = w.sum(axis=1, keepdims=True)
    w = np.where(s > 0, w / np.where(s > 0, s, 1.0), 0.0)
    return w, int((s[:, 0] <= 0).sum())


def _match(vertices, parts):
    """Index of each rig vertex in the concatenated ``parts`` (tried in every order, then
    matched in order, then by nearest neighbour), when one similarity maps one onto the
    other within 1e-4 of the diagonal; else None."""
    diag = np.linalg.norm(np.ptp(vertices, axis=0))
    offsets = np.cumsum([0] + [len(p) for p in parts])
    for order in permutations(range(len(parts))):
        pts = np.concatenate([parts[i] for i in order])
        idx = np.concatenate([np.arange(offsets[i], offsets[i + 1]) for i in order])
        if len(pts) != len(vertices):
            break
        fit = _similarity(pts, vertices)
        if np.abs(fit - vertices).max() < 1e-4 * diag:
            return idx
    pts = np.concatenate(parts)
    d, near = cKDTree(pts).query(vertices)
    return near if d.max() < 1e-4 * diag else None


def _similarity(src, dst):
    """``src`` moved by the least-squares similarity onto ``dst`` (Umeyama)."""
    ms, md = src.mean(axis=0), dst.mean(axis=0)
    a, b = src - ms, dst - md
    u, sv, vt = np.linalg.svd(b.T @ a)
    d = np.sign(np.linalg.det(u @ vt))
    r = u @ np.diag([1, 1, d]) @ vt
    scale = (sv * [1, 1, d]).sum() / max((a * a).sum(), 1e-300)
    return scale * a @ r.T + md


def variants(full):
    """The methods to measure: idw and heat, and with ``full`` the choices heat makes."""
    out = {"idw": ("idw", {}), "heat": ("heat", {})}
    if full:
        out.update({f"heat, c={c:g}": ("heat", {"c": c}) for c in (1.0, 2.0, 3.0, 8.0)})
        out["heat, min weight 0.01"] = ("heat", {"min_weight": 0.01})
        out.update({
            "heat, helpers kept": ("heat", {"helpers": False}),
            "heat, no IK chain tails": ("heat", {"ik_chains": False}),
            "heat, every part blocks": ("heat", {"own_part": False}),
            "heat, branch centroid": ("heat", {"branches": "centroid"}),
            "heat, leaf tails off": ("heat", {"infer_tails": False}),
            "heat, front-facing rule": ("heat", {"front_only": True}),
            "heat, normal-biased rank": ("heat", {"normal_bias": True}),
            "heat, behind test off": ("heat", {"behind": 2.0}),
            "heat, no min weight": ("heat", {"min_weight": 0.0}),
        })
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--blender", type=Path, default=Path("/tmp/blender_heat"),
                    help="folder of blender_bone_heat.py's .npz files")
    ap.add_argument("--variants", action="store_true")
    ap.add_argument("--only", action="append", help="character label (repeatable)")
    args = ap.parse_args(argv)
    print("error of the skinned vertices against the artist's weights, % of the rest "
          "bounding-box diagonal, every integer frame at 24 fps of one clip")
    print(f"{'character':18s} {'method':26s} {'mean':>7s} {'p95':>7s} {'max':>7s} "
          f"{'L1':>6s} {'fallback':>8s} {'time s':>7s}")
    for label, spec, skin_index in CHARACTERS:
        if args.only and label not in args.only:
            continue
        rig = load(spec, skin_index)
        clip = pick_clip(rig)
        rows = []
        bw = blender_weights(rig, args.blender / f"{Path(spec).stem}.npz") \
            if spec.endswith((".glb", ".gltf")) else None
        if bw is not None:
            rows.append(("Blender 3.4 bone heat", bw[0], bw[1], float("nan")))
        for name, (method, options) in variants(args.variants).items():
            rows.append((name, *run(method, rig, **options)))
        for name, w, fb, dt in rows:
            mean, p95, mx, l1, diag = measure(rig, clip, w)
            print(f"{label:18s} {name:26s} {mean:7.3f} {p95:7.3f} {mx:7.3f} {l1:6.3f} "
                  f"{fb:8d} {dt:7.3f}")
        print(f"{label:18s} ({len(rig.vertices)} vertices, {len(rig.skeleton)} joints, clip "
              f"{clip!r}, rest diagonal {diag:.4g})")


if __name__ == "__main__":
    main()
