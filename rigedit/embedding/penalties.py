"""Penalties of a discrete embedding (Pinocchio section 4), with the weights reasoned out.

Pinocchio learned the weights of its penalties with a support vector machine from a few
hand-rigged examples. We set them by reasoning instead, so that one unit of cost means
"clearly wrong", and say why beside each weight. Every term is scale-free: lengths are
compared as log ratios to the template's (scaled by ``scale``, mesh units per template
unit), positions as fractions of the mesh's height.

Bone terms depend on the graph vertices of a reduced bone's two ends (an (N, N) matrix per
bone, so the tree part of the cost can be minimised exactly by dynamic programming); the
mirror term couples the two sides of the body and is added during the best-first search.
"""
from __future__ import annotations

import numpy as np

__all__ = ["bone_costs", "joint_costs", "mirror_cost", "W_CARRY", "SEPARATE_RATIO",
           "W_LENGTH_TAIL"]

#: Bone length, as twice the (log ratio)^2 of the chord to the template chord (times the
#: scale): a bone 25% too long or short costs 0.1, half or twice as long ~1. Weak on
#: purpose: proportions vary between characters (a cow's long body against the elk's, a
#: cartoon's short legs), and a stronger length term made the search fold a cow's body to
#: the elk's length, hind legs in the front legs.
W_LENGTH = 1.0
#: The length term of a tail's bone (see ``template._tails``) is this fraction of a limb's: a
#: tail is a pug's stub or a horse's arc, so its length says little, while where the mesh's
#: branch ends says much (the horse's tail end stopped half-way down its tail at the full
#: weight, 8% of its size off the artist's).
W_LENGTH_TAIL = 0.2
#: Allowed excess of a path's detour (log of path over chord) over the template chain's.
DETOUR = 0.15
#: Bone direction, times (1 - cos) of the angle to the template chord: 0.9 for 45 degrees
#: (an A-pose arm against a T-pose template, still acceptable), 3 for a right angle, 6 for
#: a bone pointing backwards (a leg going up). The frames are shared (+Y up, facing +Z),
#: so direction is the strongest evidence of which part is which.
W_DIRECTION = 3.0
#: Foot height, as the squared difference of a foot's height above the ground and the
#: template's (scaled), in quarters of the mesh height: 0.16 for a tenth of the height off.
W_HEIGHT = 1.0
#: The same for the other joints: none. Characters differ in proportions (short legs, a
#: big head) far more than feet differ in height; a height prior put homer's chest in his
#: mouth.
W_HEIGHT_OTHER = 0.0
#: Symmetry, as the squared distance between a joint and its mirror partner's reflection in
#: units of 5% of the template's size (scaled): a limb 5% off its mirror costs 0.5.
W_MIRROR = 0.5
#: Price of leaving an optional branch (antlers, a tail) unembedded: about a fair fit's
#: cost for one bone, so a branch is embedded only where the mesh clearly has it.
W_CARRY = 0.5
#: Two limb ends that the template keeps far apart along the tree (the feet: the tree path
#: through the hips is many times their distance) must be separated in the mesh too: their
#: graph path must be at least this much longer than their distance. A blob fails here
#: (and so does a template whose hands hang by its hips against a mesh whose arms are out:
#: the template must stand roughly as the mesh does).
SEPARATE_RATIO = 1.4


def bone_costs(points, dist, chord, chain_length, scale, w_length=W_LENGTH):
    """(N, N) cost of a reduced bone from vertex a (rows) to vertex b (columns).

    Parameters
    ----------
    points : (N, 3) float64
        Graph vertices.
    dist : (N, N) float64
        Shortest path lengths.
    chord : (3,) float64
        Template vector from the bone's parent joint to its child.
    chain_length : float
        Template length of the chain of bones it stands for.
    scale : float
        Mesh units per template unit.
    w_length : float
        Weight of the length term (``W_LENGTH``; ``W_LENGTH * W_LENGTH_TAIL`` for a
        tail).

    Returns
    -------
    (N, N) float64, ``inf`` on the diagonal and between components.
    """
    d = points[None, :, :] - points[:, None, :]
    length = np.linalg.norm(d, axis=2)
    chord_len = max(float(np.linalg.norm(chord)), 1e-12)
    with np.errstate(divide="ignore", invalid="ignore"):
        cos = np.einsum("abk,k->ab", d, chord / chord_len) / length
        # The chord carries the length; the path (through the inside) may be longer than the
        # chord only as much as the template chain is longer than its chord, give or take:
        # beyond that the bone wanders through another part (a hand reached via the hips).
        detour = np.log(dist / length) - np.log(chain_length / chord_len)
        cost = w_length * 2.0 * np.log(length / (scale * chord_len)) ** 2
        cost += W_LENGTH * np.maximum(detour - DETOUR, 0.0) ** 2
        cost += W_DIRECTION * (1.0 - cos)
    cost[~np.isfinite(cost)] = np.inf
    np.fill_diagonal(cost, np.inf)
    return cost


def joint_costs(points, template_y, template_floor, floor, height, scale, foot):
    """(N,) cost of putting a joint at each graph vertex (its height).

    Parameters
    ----------
    points : (N, 3) float64
    template_y : float
        The joint's template height.
    template_floor : float
        Lowest template joint height.
    floor, height : float
        The mesh's lowest point and height.
    scale : float
    foot : bool
        The joint stands on the ground (an ankle, a hoof): ``W_HEIGHT``; other joints get
        ``W_HEIGHT_OTHER``.
    """
    expected = scale * (template_y - template_floor)
    weight = W_HEIGHT if foot else W_HEIGHT_OTHER
    return weight * ((points[:, 1] - floor - expected) / (0.25 * height)) ** 2


def mirror_cost(p, q, plane_x, unit):
    """Cost of joint positions ``p`` (N, 3) against their partner's ``q`` (3,) mirrored
    across x = ``plane_x``; ``unit`` is 5% of the template's size in mesh units."""
    m = np.array([2.0 * plane_x - q[0], q[1], q[2]])
    return W_MIRROR * np.sum((p - m) ** 2, axis=-1) / (unit * unit)

