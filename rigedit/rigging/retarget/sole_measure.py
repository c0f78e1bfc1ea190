"""How the feet stand on the skin: where the source's feet stand, the frames a foot stands
in, the patch it stands on and how far that slips.

A foot *stands* in the frames of a contact where the source's foot stands
(:func:`standing`, on the source's skin when it has one: :func:`source_clearance`). The
patch it stands on is its vertices lowest in a frame (:func:`bearing_steps`), and its
slip the horizontal path of that patch over a contact (:func:`sole_slip`); a foot rolling
from heel to toe turns about its lowest point and does not slip. :func:`sole_measures`
gives the figures of ``benchmarks/bench_soles.py``.

Pure numpy.
"""
from __future__ import annotations

import warnings

import numpy as np

from .contacts import runs
from .sole_skin import CHUNK, find_soles, has_skin, palette, sole_heights, vertex_heights

__all__ = ["bearing_steps", "sole_slip", "source_clearance", "foot_legs", "standing",
           "sole_measures", "STANDING", "PATCH"]

#: A foot in contact stands (on the floor, not sliding) while the source's stands within
#: this of the lowest it stands in that contact, per unit of hip height (9 mm on a human).
STANDING = 0.01
#: The patch a foot stands on: its vertices within this share of the foot's size of its
#: lowest (4 mm on a 27 cm foot).
PATCH = 0.015


def bearing_steps(soles, skeleton, mats, heights=None, patch=None):
    """How the patch each foot stands on moves: per foot, the horizontal (x, z) step from
    frame ``f`` to ``f + 1`` of the vertices lowest in frame ``f`` (within ``patch`` of the
    lowest: the heel at a heel strike, the whole sole of a flat foot, the ball at a push-off),
    on average.

    Parameters
    ----------
    soles : Soles
    skeleton : Skeleton
    mats : (F, J, 4, 4) float64
    heights : (F, N) float64, optional
        :func:`vertex_heights` of ``mats``.
    patch : float, optional
        Model units; by default :data:`PATCH` of the feet's size (the largest extent of the
        first foot's vertices in the rest pose, so a flat sole's millimetres of wobble do
        not make its one lowest vertex jump from heel to toe).

    Returns
    -------
    steps : (F - 1, n_feet, 2) float64
    """
    y = vertex_heights(soles, skeleton, mats) if heights is None else heights
    if patch is None:
        patch = PATCH * soles.size
    off = soles.offsets
    pal = palette(soles, skeleton, mats)[:, :, [0, 2], :]         # (F, U, 2, 4)
    pal = pal.transpose(0, 1, 3, 2).reshape(len(mats), -1, 2)     # (F, 4U, 2)
    out = np.zeros((max(len(mats) - 1, 0), len(off) - 1, 2))
    for i, (a, b) in enumerate(zip(off[:-1], off[1:])):
        z = np.empty((len(out), soles.lifted.shape[1]))
        for c in range(0, len(out), CHUNK):  # (frames, N) at a time: long clips fit
            ya = y[c:min(c + CHUNK, len(out)), a:b]
            near = (ya <= ya.min(axis=1, keepdims=True) + patch).astype(np.float64)
            # the patch's mean lifted vector: its mean position is linear in it
            z[c:c + len(ya)] = (near @ soles.lifted[a:b]) / near.sum(axis=1, keepdims=True)
        out[:, i] = (np.einsum("fk,fkc->fc", z, pal[1:])
                     - np.einsum("fk,fkc->fc", z, pal[:-1]))
    return out


def sole_slip(steps, contact):
    """Slip of a foot's skin during each of its contacts: the horizontal path of the patch
    bearing the weight (:func:`bearing_steps`), summed over each contact's frames. A foot
    rolling from heel to toe turns about its lowest point and does not slip; one sliding, or
    turning about its ankle, does.

    Parameters
    ----------
    steps : (F - 1, 2) float64
        One foot's bearing steps.
    contact : (F,) bool

    Returns
    -------
    slips : (C,) float64
        One per contact run, in model units.
    """
    return np.array([float(np.linalg.norm(steps[a:b - 1], axis=1).sum())
                     for a, b in runs(contact)])


def source_clearance(src, smats, s_floor, s_points, scale, source_rig=None):
    """How high the source's feet stand above where they stand standing, scaled to the
    target: on the source's skin when it has one (each foot's lowest skinned point above
    the floor its rest soles define, moved as the motion's floor is), else on its contact
    joints (``y_p(t) - s_floor - y_p(rest)``, the height
    :func:`rigedit.rigging.retarget.contacts.detect_contacts` compares with its tolerance).

    Parameters
    ----------
    src : Calibration or LegCalibration
    smats : (F, Js, 4, 4) float64
        The source's model matrices over the clip.
    s_floor : float
        The motion's floor (model y).
    s_points : list of int
        The source joint of each column of the retarget's contacts (a humanoid's left and
        right ankle and toe; else the source foot leaf of each target leg).
    scale : float
        Target / source hip height.
    source_rig : Rig, optional
        The source; its skin is used when it has a mesh that weights the feet.

    Returns
    -------
    clearance : (F, P) float64
    """
    rest = src.mats[s_points, 1, 3] - src.joint_floor
    joints = scale * (smats[:, s_points, 1, 3] - s_floor - rest[None])
    if not has_skin(source_rig):
        return joints
    if src.kind == "humanoid":
        ankles = [src.slots["foot_L"], src.slots["foot_R"]] * 2
    else:
        by_leaf = {leg.contact: leg.ankle for leg in src.legs}
        ankles = [by_leaf.get(p, p) for p in s_points]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a source without skinned feet: its joints say
        soles = find_soles(source_rig, sorted(set(ankles)), src.mats)
    if soles is None:
        return joints
    col = {a: i for i, a in enumerate(sorted(set(ankles)))}
    low = sole_heights(soles, source_rig.skeleton, smats) - soles.floor \
        - (s_floor - src.joint_floor)
    return scale * low[:, [col[a] for a in ankles]]


def foot_legs(tgt, contact, clearance=None):
    """Per foot: its IK joints ``(upper, knee, ankle)``, its contact mask and its source
    clearance.

    Parameters
    ----------
    tgt : Calibration or LegCalibration
    contact : (F, P) bool
        The retarget's contacts: a humanoid's left and right ankle, then left and right toe
        (a foot touches while either does); otherwise one column per leg.
    clearance : (F, P) float64, optional
        :func:`source_clearance` of the same columns (zeros by default).

    Returns
    -------
    legs : list of (int, int, int)
    contact : (F, n_feet) bool
    clearance : (F, n_feet) float64
        A humanoid foot's is its lower point's (the heel strikes on the ankle's, the toe
        pushes off on the toe's).
    """
    contact = np.asarray(contact, bool)
    clearance = np.zeros(contact.shape) if clearance is None else clearance
    if tgt.kind == "humanoid":
        s = tgt.slots
        legs = [(s[f"thigh_{k}"], s[f"shin_{k}"], s[f"foot_{k}"]) for k in "LR"]
        return (legs, contact[:, [0, 1]] | contact[:, [2, 3]],
                np.minimum(clearance[:, [0, 1]], clearance[:, [2, 3]]))
    return [(leg.upper, leg.knee, leg.ankle) for leg in tgt.legs], contact, clearance


def standing(clearance, contact, tol):
    """The frames a foot stands in: those of its contacts in which the source's foot stands
    within ``tol`` of the lowest it stands in that contact (mocap feet wobble by millimetres
    while they bear the weight; the contact's own tolerance also counts the first lift of a
    foot, or its setting down, which are not standing).

    Parameters
    ----------
    clearance : (F,) float64
        :func:`source_clearance` of the foot.
    contact : (F,) bool
    tol : float

    Returns
    -------
    standing : (F,) bool
    """
    out = np.zeros(len(contact), dtype=bool)
    for a, b in runs(contact):
        out[a:b] = clearance[a:b] <= clearance[a:b].min() + tol
    return out


def sole_measures(result, rig, source_rig=None):
    """How a retarget's feet stand on the skin: the figures of ``benchmarks/bench_soles.py``.

    Parameters
    ----------
    result : RetargetResult
        A retarget onto ``rig`` (a rig with a mesh whose feet have vertices).
    rig : Rig
    source_rig : Rig, optional
        The retarget's source (its skin says where its feet stand, as in the retarget).

    Returns
    -------
    dict
        ``lowest``: the lowest sole point over the clip above the floor (negative: below);
        ``below``: the share of frames in which a sole is more than 1 mm below it;
        ``standing``: the sole's height in the worst standing frame of a contact
        (:func:`standing`), signed; ``slips``: (C,) slip
        per contact over its standing frames (:func:`sole_slip`); ``floor``: the floor's
        model y. Lengths in model units.
    """
    tgt = result.target_calibration
    clear = source_clearance(result.source_calibration, result.source_mats,
                             result.source_floor, result.source_contacts, result.scale,
                             source_rig)
    legs, touch, clear = foot_legs(tgt, result.contact, clear)
    soles = find_soles(rig, [a for *_, a in legs], tgt.mats)
    y = vertex_heights(soles, rig.skeleton, result.mats)
    low = sole_heights(soles, rig.skeleton, result.mats, y) - soles.floor
    steps = bearing_steps(soles, rig.skeleton, result.mats, y)
    worst_stand, slips = 0.0, []
    for i in range(len(legs)):
        stand = standing(clear[:, i], touch[:, i], STANDING * tgt.hip_height)
        if stand.any():
            worst = low[stand, i][np.argmax(np.abs(low[stand, i]))]
            worst_stand = worst if abs(worst) > abs(worst_stand) else worst_stand
            slips.extend(sole_slip(steps[:, i], stand))
    return dict(lowest=float(low.min()), below=float((low < -1e-3).any(axis=1).mean()),
                standing=float(worst_stand), slips=np.array(slips), floor=soles.floor)
