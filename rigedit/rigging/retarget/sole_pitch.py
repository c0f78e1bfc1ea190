"""A free foot turned out of the floor: pitched about its ankle rather than lifted.

A free foot whose sole is below the floor because of its pitch (toes pointing through it
after a push-off, a heel before a strike) is turned about its ankle, the least that clears
it, at most :data:`PITCH` degrees (:func:`pitch_feet`): the foot's direction changes, not the
leg's; the ankle is lifted (:mod:`.soles`) only for what is left.

Pure numpy + scipy.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ...model.transforms import unit
from .calibrate import rotations_of
from .contacts import smooth_max
from .sole_skin import foot_low

__all__ = ["pitch_feet", "PITCH", "PITCH_STEPS"]

#: The most a foot is pitched about its ankle (degrees, toes up or heel up) to take a sole
#: out of the floor before the ankle is lifted (which bends the leg): a swing foot whose
#: toes point through the floor turns them up instead.
PITCH = 45.0
#: Pitch angles tried per side (the least that suffices is taken).
PITCH_STEPS = 12


def _turned(sk, mats, joints, turn):
    """``mats`` (F, J, 4, 4) with the foot ``joints`` (the ankle first) turned by ``turn``
    (F, 3, 3) about the ankle."""
    out = mats.copy()
    ankle = mats[:, joints[0], :3, 3]
    for j in joints:
        out[:, j, :3, :3] = turn @ mats[:, j, :3, :3]
        out[:, j, :3, 3] = ankle + np.einsum("fab,fb->fa", turn, mats[:, j, :3, 3] - ankle)
    return out


def pitch_feet(soles, sk, tgt, rot, mats, need, freedom, blend, tol):
    """Turn each foot about its ankle (toes up or heel up, at most :data:`PITCH` degrees)
    where its sole must rise: a foot pitched through the floor comes out by turning, not
    by lifting the ankle, which would bend the leg away from the source's directions.

    In each frame the least pitch that takes the sole up by ``need`` is taken (the one that
    lifts it most where none suffices; none where no pitch lifts it), scaled by
    ``freedom`` and spread over a third of ``blend`` frames either way
    (:func:`rigedit.rigging.retarget.contacts.smooth_max` on the toes-up and heels-up parts), so
    the foot does not snap (a wider spread turns frames that need no turn, and a heel then
    goes down); the legs' IK takes what is left.

    Parameters
    ----------
    soles : Soles
    sk : Skeleton
    tgt : Calibration or LegCalibration
    rot : (F, J, 3, 3) float64
        Model rotations (changed in place for the feet's joints).
    mats : (F, J, 4, 4) float64
        ``rot`` assembled.
    need : (F, n_feet) float64
        How far each foot's lowest point must rise (model units; 0 where it need not).
    freedom : (F, n_feet) float64
        0..1, how much of the pitch a foot may take (0 where it stands: turning there
        would slide the patch it stands on).
    blend : int
    tol : float
        Needs below this are none.

    Returns
    -------
    pitched : bool
        Whether any foot turned (then ``rot`` has changed and ``mats`` is stale).
    """
    pitched = False
    grid = np.radians(np.linspace(-PITCH, PITCH, 2 * PITCH_STEPS + 1))
    grid = grid[np.argsort(np.abs(grid), kind="stable")]        # the least turn first
    # about the body's left axis, as the knee bends (measured: Bandai's walk onto CesiumMan,
    # legs 4.1 degrees off the source's; 6.5 about an axis square to where each foot points)
    lateral = unit(rot[:, tgt.hips] @ (rotations_of(tgt.mats)[tgt.hips].T @ tgt.left))
    for i, joints in enumerate(soles.joints):
        fr = np.flatnonzero((need[:, i] > tol) & (freedom[:, i] > 0))
        if len(fr) == 0:
            continue
        m = mats[fr]
        axis = lateral[fr]
        base = foot_low(soles, sk, m, i)
        rise = np.stack([foot_low(soles, sk, _turned(sk, m, joints, Rotation.from_rotvec(
            axis * g).as_matrix()), i) - base for g in grid], axis=1)  # (len(fr), K)
        enough = rise >= need[fr, i, None] - tol
        best = np.where(enough.any(axis=1), np.argmax(enough, axis=1), np.argmax(rise, axis=1))
        angle = np.zeros(len(rot))
        angle[fr] = np.where(rise[np.arange(len(fr)), best] > tol, grid[best], 0.0) \
            * freedom[fr, i]
        if not angle.any():
            continue
        # each side spread on its own: a toes-up swing and a heel-up one do not cancel
        up, down = np.maximum(angle, 0.0), np.maximum(-angle, 0.0)
        angle = (smooth_max(up, max(1, blend // 3)) if up.any() else up) \
            - (smooth_max(down, max(1, blend // 3)) if down.any() else down)
        angle *= freedom[:, i]                  # still 0 where the foot stands
        turn_at = np.flatnonzero(np.abs(angle) > 1e-9)
        if len(turn_at) == 0:
            continue
        turn = Rotation.from_rotvec(lateral[turn_at] * angle[turn_at, None]).as_matrix()
        for j in joints:
            rot[turn_at, j] = turn @ rot[turn_at, j]
        pitched = True
    return pitched
