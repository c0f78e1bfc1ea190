"""Automatic weights against an artist's, measured by the deformation they give.

For each glTF character with artist weights (``../shared/data/khronos-gltf``): compute
automatic weights from its mesh and skeleton alone, skin every integer frame at 24 fps of
its first animation with the artist's weights (P_a) and with the automatic ones (P_b), same
joint and inverse bind matrices, 4 influences; the error of a vertex at a frame is
|P_a - P_b| as a percentage of the rest mesh's bounding-box diagonal. Prints mean, p95 and
max over vertices and frames, the mean L1 distance between weight rows, and how many
vertices needed a fallback, next to Blender 3.4's bone heat measured on the same files.

    .venv/bin/python benchmarks/bench_weights_quality.py [--variants]

``--variants`` also measures the choices heat makes (operator, visibility rule, tails,
ranking), for the record in the README.
"""
from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

from rigedit.io.gltf_read import load_gltf
from rigedit.model.skinning import dense_weights, top_k_influences
from rigedit.model.weights import compute_weights

DATA = Path(__file__).resolve().parents[1] / ".." / "shared" / "data" / "khronos-gltf"
FILES = ["RiggedFigure.glb", "CesiumMan.glb"]
FPS = 24
# Blender 3.4 "With Automatic Weights", measured on this machine (issue 10): mean, p95, max.
BLENDER = {"RiggedFigure": (0.105, 0.559, 2.019), "CesiumMan": (0.436, 1.115, 4.761)}


def skin(vertices, indices, weights, palette):
    """(V, 3) linear blend skinning, the reference formula."""
    blended = np.einsum("vk,vkij->vij", weights, palette[indices])
    return np.einsum("vij,vj->vi", blended[:, :3, :3], vertices) + blended[:, :3, 3]


def frames(rig):
    """Skinning palettes (J, 4, 4) of every integer frame at FPS of the first clip."""
    clip = next(iter(rig.clips.values()))
    n = int(np.floor(clip.duration * FPS + 1e-9)) + 1
    for i in range(n):
        pose = clip.sample(i / FPS)
        yield rig.joint_matrices(pose) @ rig.skeleton.inverse_bind_matrices


def measure(rig, indices, weights):
    """Error statistics (% of the diagonal) and mean L1 row distance against the artist."""
    diag = np.linalg.norm(np.ptp(rig.vertices, axis=0))
    ai, aw = top_k_influences(dense_weights(rig.binding.indices, rig.binding.weights,
                                            len(rig.skeleton)), 4)
    bi, bw = top_k_influences(dense_weights(indices, weights, len(rig.skeleton)), 4)
    errs = []
    for palette in frames(rig):
        pa = skin(rig.vertices, ai, aw, palette)
        pb = skin(rig.vertices, bi, bw, palette)
        errs.append(np.linalg.norm(pa - pb, axis=1))
    e = 100.0 * np.concatenate(errs) / diag
    j = len(rig.skeleton)
    l1 = np.abs(dense_weights(ai, aw, j) - dense_weights(bi, bw, j)).sum(axis=1).mean()
    return e.mean(), np.percentile(e, 95), e.max(), l1


def run(method, rig, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t = time.perf_counter()
        res = compute_weights(rig.vertices, rig.skeleton, method, max_influences=4,
                              faces=rig.faces, **options)
        dt = time.perf_counter() - t
    fallback = len(getattr(res, "fallback", ()))
    return (*measure(rig, *res), fallback, dt)


def main(argv):
    variants = {"idw": ("idw", {}), "heat": ("heat", {})}
    if "--variants" in argv:
        variants.update({
            "heat, leaf tails off": ("heat", {"infer_tails": False}),
            "heat, front-facing rule": ("heat", {"front_only": True}),
            "heat, normal-biased rank": ("heat", {"normal_bias": True}),
            "heat, behind test off": ("heat", {"behind": 2.0}),
            "heat, behind < 0": ("heat", {"behind": 0.0}),
            "heat, behind < -0.1": ("heat", {"behind": -0.1}),
            "heat, behind < -0.3": ("heat", {"behind": -0.3}),
            "heat, behind < 0.5": ("heat", {"behind": 0.5}),
            "heat, robust-laplacian": ("heat", {"operator": "robust"}),
            "heat, no min weight": ("heat", {"min_weight": 0.0}),
            "heat, min weight 0.05": ("heat", {"min_weight": 0.05}),
        })
    print("error of the skinned vertices against the artist's weights, % of the bounding-box "
          "diagonal, all integer frames at 24 fps of the first clip")
    print(f"{'character':14s} {'method':28s} {'mean':>7s} {'p95':>7s} {'max':>7s} "
          f"{'L1':>6s} {'fallback':>8s} {'time s':>7s}")
    for name in FILES:
        path = DATA / name
        if not path.exists():
            print(f"{name}: not found under {DATA}")
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rig = load_gltf(path)
        stem = path.stem
        b = BLENDER.get(stem)
        if b:
            print(f"{stem:14s} {'Blender 3.4 bone heat':28s} {b[0]:7.3f} {b[1]:7.3f} {b[2]:7.3f}")
        for label, (method, options) in variants.items():
            mean, p95, mx, l1, fb, dt = run(method, rig, **options)
            print(f"{stem:14s} {label:28s} {mean:7.3f} {p95:7.3f} {mx:7.3f} {l1:6.3f} "
                  f"{fb:8d} {dt:7.3f}")


if __name__ == "__main__":
    main(sys.argv[1:])
