"""The soles held on the floor: each foot's lowest skinned point on it where the foot
stands, not sliding, and never below it.

The foot clean-up of :mod:`.contacts` works on joints (ankle, toe, their tails), but what the
user sees is the skin: a sole lies a few centimetres below the ankle joint, and how far
depends on the mesh, not on the skeleton. So each foot is measured on its skinned vertices
(:mod:`.sole_skin`: the vertices its joints dominate, and the floor they define in the
target's calibration pose), and :func:`hold_soles` corrects the cleaned-up motion. A foot
*stands* in the frames of a contact where the source's foot stands (:mod:`.sole_measure`);
there its lowest skinned point goes onto the floor and the patch it stands on does not slide
(:func:`hold_offsets`), both changes faded in and out as the joints' pins are
(:func:`fade_runs`); in every other frame a sole below the floor is lifted. Where every foot
on the ground must rise (or sink) the body does, by the least of them (:func:`raise_body`);
the rest moves each ankle's IK goal (the foot keeps its model rotation, so the skin it
carries moves with the ankle; where the shin carries part of it a measured gain per frame
makes up the difference), the hips dropping where a leg cannot reach
(:func:`rigedit.rigging.retarget.contacts.solve_legs`). A free foot whose sole is below the
floor because of its pitch is first turned about its ankle (:mod:`.sole_pitch`); the ankle
is lifted only for what is left.

The names of :mod:`.sole_skin`, :mod:`.sole_measure` and :mod:`.sole_pitch` are importable
from here too, as they were before those modules were split off.

Pure numpy + scipy.
"""
from __future__ import annotations

import warnings

import numpy as np

from .bake import assemble
from .contacts import blend_frames, ramp, runs, smooth_max, solve_legs
# used here, and importable from here as before the split
from .sole_measure import (PATCH, STANDING, bearing_steps, foot_legs, sole_measures,
                           sole_slip, source_clearance, standing)
from .sole_pitch import PITCH, PITCH_STEPS, pitch_feet
from .sole_skin import (CHUNK, DOMINANT, Soles, find_soles, skin_points, sole_heights,
                        vertex_heights)

__all__ = ["Soles", "find_soles", "skin_points", "vertex_heights", "sole_heights",
           "bearing_steps", "sole_slip", "hold_offsets", "fade_runs", "source_clearance",
           "foot_legs", "standing", "raise_body", "pitch_feet", "hold_soles",
           "sole_measures", "DOMINANT", "TOLERANCE", "STANDING", "PATCH", "PITCH"]

#: Corrections stop once every foot's lowest point is within this of its goal, per unit of
#: hip height (0.1 mm on a figure whose hips stand 1 m high).
TOLERANCE = 1e-4
#: Rounds of IK and re-measuring at most: the skin moves with the ankle but for the vertices
#: the shin shares, and a hips drop moves the other foot.
ROUNDS = 8


def hold_offsets(steps, contact, blend):
    """Horizontal offsets that stop a foot's skin slipping during its contacts.

    In each contact the foot is moved so that the patch bearing the weight in a frame
    stays where it is in the next (the foot turns about the point it stands on: a heel
    strike rolls onto the ball, a pivot turns about it); the offsets are centred on the
    contact (the foot stands where it stood on average) and faded in before it and out after
    it over ``blend`` frames, as :func:`rigedit.rigging.retarget.contacts.pin_offsets` fades the
    joints' pins.

    Parameters
    ----------
    steps : (F - 1, 2) float64
        One foot's bearing steps (:func:`bearing_steps`).
    contact : (F,) bool
    blend : int

    Returns
    -------
    offsets : (F, 2) float64
        To add to the foot's x and z.
    """
    held = np.zeros((len(contact), 2))
    for a, b in runs(contact):
        held[a + 1:b] = -np.cumsum(steps[a:b - 1], axis=0)
        held[a:b] -= held[a:b].mean(axis=0)
    return fade_runs(held, contact, blend)


def fade_runs(values, mask, blend):
    """``values`` (F, ...) inside the runs of the (F,) bool ``mask``, 0 elsewhere but for the
    ``blend`` frames either side of a run, which take the run's edge value faded by
    :func:`rigedit.rigging.retarget.contacts.ramp`'s weight (the nearer run's where two meet)."""
    n = len(mask)
    out = np.zeros_like(values)
    best = np.zeros(n)
    for a, b in runs(mask):
        out[a:b], best[a:b] = values[a:b], 1.0
        for k in range(1, blend + 1):
            w = 1.0 - k / (blend + 1)
            for f, edge in ((a - k, a), (b - 1 + k, b - 1)):
                if 0 <= f < n and w > best[f]:
                    best[f], out[f] = w, w * values[edge]
    return out


def _onto_floor(low, held, blend):
    """(F, n_feet) the height change that puts each sole on the floor where its foot stands
    (``held``), faded out before and after (:func:`fade_runs`)."""
    return np.stack([fade_runs(-low[:, i], held[:, i], blend) for i in range(low.shape[1])],
                    axis=1)


def raise_body(weights, change, blend):
    """How far to raise (or lower) the body so that the feet on the ground move as they must
    without bending the legs: in each frame where every foot on the ground (weight above 0)
    must go up, the least they must; where every one must go down, minus the least they
    must; else 0 (and where none touches); averaged over ``2 blend + 1`` frames so the body
    does not jolt (the legs' IK takes what is left, either way).

    Parameters
    ----------
    weights : (F, n_feet) float64
        Each foot's contact weight (:func:`rigedit.rigging.retarget.contacts.ramp`).
    change : (F, n_feet) float64
        The height change each foot's sole needs.
    blend : int

    Returns
    -------
    raise_by : (F,) float64
    """
    on = weights > 0
    up = np.where(on, change, np.inf).min(axis=1)
    down = np.where(on, change, -np.inf).max(axis=1)
    need = np.where(up > 0, up, np.where(down < 0, down, 0.0))
    need[~on.any(axis=1)] = 0.0
    if not need.any():
        return need
    kernel = np.ones(2 * blend + 1) / (2 * blend + 1)
    return np.convolve(np.pad(need, blend, mode="edge"), kernel, mode="valid")


def _move_feet(sk, tgt, rot, hips_pos, mats, legs, move, blend, mapped):
    """Each leg's ankle moved by ``move`` (F, n_feet, 3) by two-bone IK (the hips dropping
    where a leg cannot reach); returns ``rot``, ``hips_pos``, ``mats``."""
    solve = [(upper, knee, mats[:, ankle, :3, 3], mats[:, ankle, :3, 3] + move[:, i])
             for i, (upper, knee, ankle) in enumerate(legs)]
    rot, drop = solve_legs(sk, tgt, rot, mats, solve, blend, mapped)
    hips_pos = hips_pos.copy()
    hips_pos[:, 1] -= drop
    return rot, hips_pos, assemble(sk, rot, tgt.hips, hips_pos)


def _heights(soles, sk, mats):
    """``(y, low)``: :func:`vertex_heights` of ``mats`` and each foot's lowest point above
    the floor, (F, n_feet)."""
    y = vertex_heights(soles, sk, mats)
    return y, sole_heights(soles, sk, mats, y) - soles.floor


def hold_soles(rig, tgt, rot, hips_pos, mats, contact, clearance, times, mapped,
               what="target"):
    """Each foot's lowest skinned point on the floor during its contacts (where the source's
    foot stands), not sliding, and never below the floor.

    Parameters
    ----------
    rig : Rig
        The target; a rig without a mesh (or with a foot no vertex is mostly weighted to)
        is returned unchanged: its joints were kept on the floor by :mod:`.contacts`.
    tgt : Calibration or LegCalibration
        The target's calibration (the floor is measured in its pose).
    rot : (F, J, 3, 3) float64
        Model rotations after the joint clean-up.
    hips_pos : (F, 3) float64
        The hips' model position.
    mats : (F, J, 4, 4) float64
        ``assemble(rig.skeleton, rot, tgt.hips, hips_pos)``.
    contact : (F, P) bool
        See :func:`foot_legs`.
    clearance : (F, P) float64 or None
        :func:`source_clearance`: during a contact the sole stands on the floor while the
        source's foot stands (:func:`standing`), and is free while the source lifts it; None
        holds it on the floor throughout.
    times : (F,) float64
    mapped : dict or set
        Target joints the map reaches (others below a leg's top keep their rest pose).
    what : str
        Names the target in a warning.

    Returns
    -------
    rot, hips_pos, mats
        Corrected, in the same shapes (the inputs are not changed).
    """
    sk = rig.skeleton
    legs, touch, clear = foot_legs(tgt, contact, clearance)
    soles = find_soles(rig, [ankle for *_, ankle in legs], tgt.mats, what)
    if soles is None:
        return rot, hips_pos, mats
    blend = blend_frames(times)
    tol = TOLERANCE * tgt.hip_height
    # the frames a foot stands in: contacts, less those in which the source lifts it
    held = np.stack([standing(clear[:, i], touch[:, i], STANDING * tgt.hip_height)
                     for i in range(len(legs))], axis=1)
    rot, hips_pos = rot.copy(), np.array(hips_pos, dtype=np.float64)
    mats, y, low = _raise_where_all_must(soles, sk, tgt, rot, hips_pos, mats, held, blend)
    goal, mats, y, low = _goal_heights(soles, sk, tgt, rot, hips_pos, mats, y, low, held,
                                       blend, tol)
    rot, hips_pos, mats, low = _follow_goal(soles, sk, tgt, rot, hips_pos, mats, y, low,
                                            legs, held, goal, blend, tol, mapped)
    off = (np.abs(goal - low) > 1e-3 * tgt.hip_height).any(axis=1)
    if off.any():  # the rounds ran out: say so, not silently
        warnings.warn(f"{what}: the skinned soles stay up to {1000 * np.abs(goal - low).max():.1f}"
                      f" mm off where they should stand in {int(off.sum())} of {len(times)} "
                      f"frames (the feet's skin does not follow the ankles)", stacklevel=2)
    return rot, hips_pos, mats


def _raise_where_all_must(soles, sk, tgt, rot, hips_pos, mats, held, blend):
    """Where every foot on the ground sinks (the joints stand where they should but the skin
    reaches lower than they say), the body rises; where every one floats it sinks: the legs
    keep the source's directions (:func:`raise_body`).

    ``hips_pos`` (F, 3) is changed in place; returns ``mats`` (F, J, 4, 4) and the heights
    ``y`` (F, N), ``low`` (F, n_feet) measured in them (:func:`_heights`)."""
    w = np.stack([ramp(held[:, i], blend) for i in range(held.shape[1])], axis=1)
    y, low = _heights(soles, sk, mats)
    onto = _onto_floor(low, held, blend)
    raise_by = raise_body(w, onto, blend)
    if raise_by.any():
        hips_pos[:, 1] += raise_by
        mats = assemble(sk, rot, tgt.hips, hips_pos)
        y, low = _heights(soles, sk, mats)
    return mats, y, low


def _goal_heights(soles, sk, tgt, rot, hips_pos, mats, y, low, held, blend, tol):
    """The height each sole must reach above the floor, (F, n_feet): standing, the floor
    (the change faded out before and after as the joints' pins are); free, out of it.

    A sole through the floor where its foot is free is first pitched out (toes or heel up,
    :func:`pitch_feet`, changing ``rot`` in place); the lift of the ankle only takes what is
    left, so the legs keep their bend. Returns ``goal`` and the ``mats``, ``y`` and ``low``
    of the (maybe pitched) pose."""
    onto = _onto_floor(low, held, blend)
    need = np.where(held, 0.0, np.maximum(0.0, -(low + onto)))
    if need.max() > tol and pitch_feet(soles, sk, tgt, rot, mats, need, ~held, blend, tol):
        mats = assemble(sk, rot, tgt.hips, hips_pos)
        y, low = _heights(soles, sk, mats)
        onto = _onto_floor(low, held, blend)
    # what the pitch leaves is lifted, spread over a third of the fade's width (a wider
    # spread bends the leg through the whole swing for a few frames' need)
    lift = np.where(held, 0.0, np.maximum(0.0, -(low + onto)))
    lift = np.stack([smooth_max(c, max(1, blend // 3)) if c.any() else c for c in lift.T],
                    axis=1)
    return low + onto + np.where(held, 0.0, lift), mats, y, low


def _follow_goal(soles, sk, tgt, rot, hips_pos, mats, y, low, legs, held, goal, blend, tol,
                 mapped):
    """Up to :data:`ROUNDS` rounds of leg IK and re-measuring that take each sole to its
    ``goal`` height and stop the skin sliding while it stands (the joints' pins hold the
    ankle and toe, but a foot turning about its ankle still slides its sole).

    Returns ``rot``, ``hips_pos``, ``mats`` and the soles' last ``low`` (F, n_feet)."""
    gain = np.ones_like(low)
    zero = np.zeros((len(low), len(legs)))
    for _ in range(ROUNDS):
        steps = bearing_steps(soles, sk, mats, y)
        across = np.stack([hold_offsets(steps[:, i], held[:, i], blend)
                           for i in range(len(legs))], axis=1)
        slide = np.abs(across).max() > tol
        if slide:  # across first, so that the heights' gain below measures heights alone
            move = np.stack([across[..., 0], zero, across[..., 1]], axis=-1)
            rot, hips_pos, mats = _move_feet(sk, tgt, rot, hips_pos, mats, legs, move,
                                             blend, mapped)
            y, low = _heights(soles, sk, mats)
        if np.abs(goal - low).max() <= tol:
            if slide:
                continue
            break
        change = (goal - low) / gain
        rot, hips_pos, mats = _move_feet(sk, tgt, rot, hips_pos, mats, legs,
                                         np.stack([zero, change, zero], axis=-1), blend,
                                         mapped)
        before = low
        y, low = _heights(soles, sk, mats)
        # how far the sole moved per unit the ankle did (under 1 where the knee's bone
        # carries part of the sole, over 1 where its turn swings a long foot): the next
        # round divides by it, a secant step per frame and foot
        moved = np.abs(change) > tol
        gain = np.where(moved, np.clip((low - before) / np.where(moved, change, 1.0),
                                       0.3, 3.0), gain)
    return rot, hips_pos, mats, low
