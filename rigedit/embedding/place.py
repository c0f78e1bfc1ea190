"""From embedded reduced joints to every template joint.

* Inner joints of a reduced bone's chain (elbows, knees, spine joints) follow the template
  chain mapped onto the embedded bone: the template chain is turned by the least rotation
  that takes its chord onto the embedded chord and scaled to the embedded chord's length,
  so the template's bends and proportions along the chain are kept. Where the embedded
  chain bends (a crouch, a bent elbow), ``bend`` pulls each inner joint to the point at
  the same fraction of length along the chain's path through the medial graph.
* Carried joints (short tips, a non-deforming root, unembedded optional branches) keep
  their template offset from the nearest placed ancestor, turned like that ancestor's bone
  and scaled by the global scale; a root above everything follows the reduced root.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ..model.ik import rotation_between

__all__ = ["least_rotation", "place_chains", "place_carried"]


def least_rotation(a, b):
    """The least rotation taking direction ``a`` (3,) onto direction ``b`` (3,)."""
    la, lb = np.linalg.norm(a), np.linalg.norm(b)
    if la < 1e-12 or lb < 1e-12 or not np.isfinite(la * lb):
        return Rotation.identity()  # a zero-length bone has no direction to turn
    return rotation_between(np.asarray(a, float), np.asarray(b, float))


def _along(polyline, fractions):
    """Points at arc-length ``fractions`` (K,) of a polyline (P, 3) -> (K, 3)."""
    seg = np.linalg.norm(np.diff(polyline, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    if cum[-1] <= 0:
        return np.repeat(polyline[:1], len(fractions), axis=0)
    return np.stack([np.interp(np.asarray(fractions) * cum[-1], cum, polyline[:, d])
                     for d in range(3)], axis=1)


def place_chains(template, reduced, paths=None, bend=0.75, scale=None):
    """Positions of the joints of the embedded chains (reduced joints and inner ones).

    Parameters
    ----------
    template : ReducedTemplate
    reduced : (R, 3) float64
        Embedded reduced joints, NaN rows where carried.
    paths : list of (P, 3) float64 or None, optional
        For each reduced joint, the polyline of its embedded chain (parent to joint).
    bend : float
        How far inner joints move from the mapped template chain towards the path: mostly
        (a bent knee or elbow is where the medial path bends), not wholly (the path zigzags
        between sphere centres). 0.75 measured best of 0.5, 0.75 and 1 on the posed bundled
        characters and the Khronos figures (``benchmarks/bench_embedding.py``).
    scale : float, optional
        Mesh units per template unit: with it a tail's root joint keeps its scaled template
        offset from the tail's base and only the tail's own bones spread along its path.

    Returns
    -------
    (J, 3) float64
        NaN rows for the joints left to :func:`place_carried`.
    """
    rest = template.rest
    out = np.full((len(rest), 3), np.nan)
    for r, j in enumerate(template.joints):
        if np.all(np.isfinite(reduced[r])):
            out[j] = reduced[r]
    for r in range(1, len(template.joints)):
        if not np.all(np.isfinite(reduced[r])):
            continue
        chain = template.chains[r]
        a, b = chain[0], chain[-1]
        inner = chain[1:-1]
        if not inner:
            continue
        rot = least_rotation(rest[b] - rest[a], out[b] - out[a])
        k = np.linalg.norm(out[b] - out[a]) / max(np.linalg.norm(rest[b] - rest[a]), 1e-12)
        mapped = out[a] + k * rot.apply(rest[inner] - rest[a])
        path = paths[r] if paths is not None else None
        if path is not None and len(path) > 2 and bend > 0:
            bones = np.linalg.norm(np.diff(rest[chain], axis=0), axis=1)
            if scale is not None and template.tail is not None and template.tail[r] \
                    and len(inner) > 1:
                # a tail: its root stays where the template has it off its base (the body's
                # edge), the rest spread along the path beyond it (a long tail stretches its
                # own bones, not the base's)
                mapped[0] = out[a] + scale * (rest[inner[0]] - rest[a])
                start = int(np.argmin(np.linalg.norm(path - mapped[0], axis=1)))
                path = np.concatenate([mapped[:1], path[start + 1:]])
                if len(path) < 2:
                    path = np.concatenate([mapped[:1], out[b][None]])
                frac = np.cumsum(bones[1:])[:-1] / max(bones[1:].sum(), 1e-12)
                mapped[1:] = (1.0 - bend) * mapped[1:] + bend * _along(path, frac)
            else:
                frac = np.cumsum(bones)[:-1] / max(bones.sum(), 1e-12)
                mapped = (1.0 - bend) * mapped + bend * _along(path, frac)
        out[inner] = mapped
    return out


def place_carried(template, positions, scale, floor=None):
    """Fill in the carried joints from the placed ones.

    Each keeps its template offset from its nearest placed ancestor, scaled, and turned like
    that ancestor's own bone (the least rotation from its template bone to its placed bone);
    a joint above every placed one (a ground-level root) keeps its offset from the reduced
    root, unturned, but its height above the ground (``floor``, the mesh's lowest point).

    Parameters
    ----------
    template : ReducedTemplate
    positions : (J, 3) float64
        NaN rows for the joints to place.
    scale : float
    floor : float, optional

    Returns
    -------
    (J, 3) float64
    """
    rest, parents = template.rest, template.parents
    out = np.array(positions, dtype=np.float64)
    placed = np.all(np.isfinite(out), axis=1)
    root = template.joints[0]
    turn = {}
    for j in range(len(rest)):
        if placed[j]:
            continue
        p = parents[j]
        while p >= 0 and not placed[p]:
            p = parents[p]
        if p < 0:
            out[j] = out[root] + scale * (rest[j] - rest[root])
            if floor is not None:  # keep its height above the ground (a ground-level root)
                out[j, 1] = floor + scale * (rest[j, 1] - template.floor)
            continue
        if p not in turn:
            q = parents[p]
            turn[p] = (least_rotation(rest[p] - rest[q], out[p] - out[q])
                       if q >= 0 and placed[q] else Rotation.identity())
        out[j] = out[p] + scale * turn[p].apply(rest[j] - rest[p])
    return out
