"""The soles: each foot's skinned vertices, their lowest point per frame, and its slip.

The foot clean-up of :mod:`.contacts` works on joints (ankle, toe, their tails), but what the
user sees is the skin: a sole lies a few centimetres below the ankle joint, and how far
depends on the mesh, not on the skeleton. Here each foot is the set of vertices its joints
dominate in the skin binding (at least :data:`DOMINANT` of their weight on the foot's
joints: the ankle joint and every joint below it), skinned on their own, and the floor is
the lowest of those points in the target's calibration pose (its rest: a rest-pose
character stands on its floor, as the joint clean-up assumes).

Skinning only heights is cheap: a vertex's linear-blend position is linear in its *lifted*
vector ``z = (w_u [v, 1])_u`` over the U joints the feet use, so the heights of N vertices
in F frames are one (N, 4U) x (4U, F) matrix product (Xbot's 3,574 foot vertices over CMU
131_01's 994 frames: a few hundredths of a second; heights are kept in float32).

:func:`hold_soles` then corrects the cleaned-up motion. A foot *stands* in the frames of a
contact where the source's foot stands (:func:`standing`, on the source's skin when it has
one: :func:`source_clearance`); there its lowest skinned point goes onto the floor and the
patch it stands on does not slide (:func:`hold_offsets`), both changes faded in and out as
the joints' pins are (:func:`fade_runs`); in every other frame a sole below the floor is
lifted. Where every foot on the ground must rise (or sink) the body does, by the least of
them (:func:`raise_body`); the rest moves each ankle's IK goal (the foot keeps its model
rotation, so the skin it carries moves with the ankle; where the shin carries part of it a
measured gain per frame makes up the difference), the hips dropping where a leg cannot
reach (:func:`rigedit.rigging.retarget.contacts.solve_legs`). A free foot whose sole is below the
floor because of its pitch (toes pointing through it after a push-off, a heel before a
strike) is first turned about its ankle, the least that clears it, at most :data:`PITCH`
degrees (:func:`pitch_feet`): the foot's direction changes, not the leg's; the ankle is
lifted only for what is left.

Pure numpy + scipy.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial.transform import Rotation

from .bake import assemble
from .calibrate import rotations_of
from ...model.transforms import unit
from .contacts import blend_frames, ramp, runs, smooth_max, solve_legs

__all__ = ["Soles", "find_soles", "skin_points", "vertex_heights", "sole_heights",
           "bearing_steps", "sole_slip", "hold_offsets", "fade_runs", "source_clearance",
           "foot_legs", "standing", "raise_body", "pitch_feet", "hold_soles",
           "sole_measures", "DOMINANT", "TOLERANCE", "STANDING", "PATCH", "PITCH"]

#: A vertex belongs to a foot when at least this much of its weight is on the foot's joints.
DOMINANT = 0.5
#: Corrections stop once every foot's lowest point is within this of its goal, per unit of
#: hip height (0.1 mm on a figure whose hips stand 1 m high).
TOLERANCE = 1e-4
#: A foot in contact stands (on the floor, not sliding) while the source's stands within
#: this of the lowest it stands in that contact, per unit of hip height (9 mm on a human).
STANDING = 0.01
#: Rounds of IK and re-measuring at most: the skin moves with the ankle but for the vertices
#: the shin shares, and a hips drop moves the other foot.
ROUNDS = 8
#: Frames measured at once (bounds the (frames, N) buffers of a long clip).
CHUNK = 512
#: The patch a foot stands on: its vertices within this share of the foot's size of its
#: lowest (4 mm on a 27 cm foot).
PATCH = 0.015
#: The most a foot is pitched about its ankle (degrees, toes up or heel up) to take a sole
#: out of the floor before the ankle is lifted (which bends the leg): a swing foot whose
#: toes point through the floor turns them up instead.
PITCH = 45.0
#: Pitch angles tried per side (the least that suffices is taken).
PITCH_STEPS = 12



@dataclass
class Soles:
    """The skinned feet of a rig.

    Attributes
    ----------
    joints : list of list of int
        Per foot, its joints (the ankle and everything below it).
    vertices : list of (N_i,) int64
        Per foot, the mesh vertices its joints dominate (never empty).
    used : (U,) int64
        The joints those vertices are weighted to (a few: the palette is computed for them
        alone).
    lifted : (sum N_i, 4 U) float64
        Each vertex's lifted vector ``(w_u x, w_u y, w_u z, w_u)`` over ``used``, foot after
        foot: its skinned position is ``sum_u K_u[:3] (w_u [v, 1])``.
    floor : float
        Model y of the lowest sole point in the calibration pose.
    size : float
        The largest extent of the first foot's vertices in that pose.
    """

    joints: list
    vertices: list
    used: np.ndarray
    lifted: np.ndarray
    floor: float = 0.0
    size: float = 1.0

    @property
    def offsets(self):
        """(n_feet + 1,) where each foot's rows start in :attr:`lifted`."""
        return np.r_[0, np.cumsum([len(v) for v in self.vertices])]


def _has_skin(rig):
    binding = getattr(rig, "binding", None)
    return binding is not None and binding.num_vertices > 0


def find_soles(rig, feet, calibration_mats, what="target"):
    """The feet of ``rig`` on its skin, or None for a rig without a mesh.

    Parameters
    ----------
    rig : Rig
        Or anything with its ``skeleton`` and ``binding`` (a :class:`SkinBinding`); one
        without a binding (the editor's snapshot of a skeleton and clips) has no skin here.
    feet : list of int
        The ankle joint of each foot; the foot is its subtree.
    calibration_mats : (J, 4, 4) float64
        The standing pose the floor is measured in.
    what : str
        Names the rig in the warning below.

    Returns
    -------
    Soles or None
        None (with a warning naming the joint) also when some foot dominates no vertex:
        then the feet are kept on the floor by their joints, as the skin cannot say.
    """
    if not _has_skin(rig):
        return None
    sk, binding = rig.skeleton, rig.binding
    weights = sp.csr_matrix(binding.matrix, dtype=np.float64)
    joints = [list(sk.subtree(a)) for a in feet]
    vertices = []
    for ankle, js in zip(feet, joints):
        share = np.asarray(weights[:, js].sum(axis=1)).ravel()
        v = np.flatnonzero(share >= DOMINANT)
        if len(v) == 0:
            warnings.warn(f"{what}: no vertex is mostly weighted to the foot below "
                          f"{sk.names[ankle]!r}; the feet are kept on the floor by their "
                          f"joints, not their skin", stacklevel=2)
            return None
        vertices.append(v)
    allv = np.concatenate(vertices)
    w = weights[allv]
    used = np.unique(w.indices)
    w = w[:, used].toarray()
    rest = np.c_[binding.rest_vertices[allv], np.ones(len(allv))]
    lifted = (w[:, :, None] * rest[:, None, :]).reshape(len(allv), 4 * len(used))
    soles = Soles(joints, vertices, used, lifted)
    rest_pts = skin_points(soles, sk, calibration_mats[None])[0]
    soles.floor = float(rest_pts[:, 1].min())
    soles.size = float(np.ptp(rest_pts[:len(vertices[0])], axis=0).max()) or 1.0
    return soles


def _palette(soles, skeleton, mats):
    """(F, U, 4, 4) skinning matrices ``M_u . inverse_bind_u`` of the joints used."""
    return mats[:, soles.used] @ skeleton.inverse_bind_matrices[soles.used][None]


def skin_points(soles, skeleton, mats, rows=None):
    """(F, N, 3) skinned positions (linear blend) of the feet's vertices (``rows`` of them,
    all by default) in the poses ``mats`` (F, J, 4, 4)."""
    z = soles.lifted if rows is None else soles.lifted[rows]
    pal = _palette(soles, skeleton, mats)[:, :, :3, :]            # (F, U, 3, 4)
    p = z @ pal.transpose(1, 3, 0, 2).reshape(z.shape[1], -1)     # (N, F x 3)
    return p.reshape(len(z), len(mats), 3).transpose(1, 0, 2)


def vertex_heights(soles, skeleton, mats):
    """(F, N) float32 model y of every foot vertex in the poses ``mats`` (F, J, 4, 4)
    (float32: a long clip's frames times thousands of vertices stay a few tens of MB, and
    a tenth of a micrometre is precise enough for a floor)."""
    pal = _palette(soles, skeleton, mats)[:, :, 1, :]             # (F, U, 4)
    out = np.empty((len(mats), len(soles.lifted)), dtype=np.float32)
    for c in range(0, len(mats), CHUNK):
        out[c:c + CHUNK] = (soles.lifted @ pal[c:c + CHUNK].reshape(len(pal[c:c + CHUNK]),
                                                                      -1).T).T
    return out


def sole_heights(soles, skeleton, mats, heights=None):
    """(F, n_feet) float64 model y of each foot's lowest skinned point in each pose (from
    ``heights``, :func:`vertex_heights` of ``mats``, when given)."""
    y = vertex_heights(soles, skeleton, mats) if heights is None else heights
    off = soles.offsets
    return np.stack([y[:, a:b].min(axis=1) for a, b in zip(off[:-1], off[1:])],
                    axis=1).astype(np.float64)


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
    pal = _palette(soles, skeleton, mats)[:, :, [0, 2], :]        # (F, U, 2, 4)
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
    if not _has_skin(source_rig):
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


def _turned(sk, mats, joints, turn):
    """``mats`` (F, J, 4, 4) with the foot ``joints`` (the ankle first) turned by ``turn``
    (F, 3, 3) about the ankle."""
    out = mats.copy()
    ankle = mats[:, joints[0], :3, 3]
    for j in joints:
        out[:, j, :3, :3] = turn @ mats[:, j, :3, :3]
        out[:, j, :3, 3] = ankle + np.einsum("fab,fb->fa", turn, mats[:, j, :3, 3] - ankle)
    return out


def _foot_low(soles, skeleton, mats, i):
    """(F,) model y of foot ``i``'s lowest skinned point in the poses ``mats``."""
    a, b = soles.offsets[i], soles.offsets[i + 1]
    pal = _palette(soles, skeleton, mats)[:, :, 1, :].reshape(len(mats), -1)
    return (soles.lifted[a:b] @ pal.T).min(axis=0)


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
        base = _foot_low(soles, sk, m, i)
        rise = np.stack([_foot_low(soles, sk, _turned(sk, m, joints, Rotation.from_rotvec(
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


def _move_feet(sk, tgt, rot, hips_pos, mats, legs, move, blend, mapped):
    """Each leg's ankle moved by ``move`` (F, n_feet, 3) by two-bone IK (the hips dropping
    where a leg cannot reach); returns ``rot``, ``hips_pos``, ``mats``."""
    solve = [(upper, knee, mats[:, ankle, :3, 3], mats[:, ankle, :3, 3] + move[:, i])
             for i, (upper, knee, ankle) in enumerate(legs)]
    rot, drop = solve_legs(sk, tgt, rot, mats, solve, blend, mapped)
    hips_pos = hips_pos.copy()
    hips_pos[:, 1] -= drop
    return rot, hips_pos, assemble(sk, rot, tgt.hips, hips_pos)


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
    w = np.stack([ramp(held[:, i], blend) for i in range(len(legs))], axis=1)
    rot, hips_pos = rot.copy(), np.array(hips_pos, dtype=np.float64)
    y = vertex_heights(soles, sk, mats)
    low = sole_heights(soles, sk, mats, y) - soles.floor
    # where every foot on the ground sinks (the joints stand where they should but the skin
    # reaches lower than they say), the body rises, where every one floats it sinks: the
    # legs keep the source's directions
    onto = _onto_floor(low, held, blend)
    raise_by = raise_body(w, onto, blend)
    if raise_by.any():
        hips_pos[:, 1] += raise_by
        mats = assemble(sk, rot, tgt.hips, hips_pos)
        y = vertex_heights(soles, sk, mats)
        low = sole_heights(soles, sk, mats, y) - soles.floor
    # standing, the sole goes onto the floor, the change faded out before and after as the
    # joints' pins are; elsewhere a sole below the floor is turned out of it, then lifted
    onto = _onto_floor(low, held, blend)
    # a sole through the floor where the foot is free: pitch the foot first (toes or heel
    # up), the ankle's lift below only takes what is left, and the legs keep their bend
    need = np.where(held, 0.0, np.maximum(0.0, -(low + onto)))
    if need.max() > tol and pitch_feet(soles, sk, tgt, rot, mats, need, ~held, blend, tol):
        mats = assemble(sk, rot, tgt.hips, hips_pos)
        y = vertex_heights(soles, sk, mats)
        low = sole_heights(soles, sk, mats, y) - soles.floor
        onto = _onto_floor(low, held, blend)
    # what the pitch leaves is lifted, spread over a third of the fade's width (a wider
    # spread bends the leg through the whole swing for a few frames' need)
    lift = np.where(held, 0.0, np.maximum(0.0, -(low + onto)))
    lift = np.stack([smooth_max(c, max(1, blend // 3)) if c.any() else c for c in lift.T],
                    axis=1)
    goal = low + onto + np.where(held, 0.0, lift)
    # the skin does not slide while it stands (the joints' pins hold the ankle and toe, but
    # a foot turning about its ankle still slides its sole)
    gain = np.ones_like(low)
    zero = np.zeros((len(times), len(legs)))
    for _ in range(ROUNDS):
        steps = bearing_steps(soles, sk, mats, y)
        across = np.stack([hold_offsets(steps[:, i], held[:, i], blend)
                           for i in range(len(legs))], axis=1)
        slide = np.abs(across).max() > tol
        if slide:  # across first, so that the heights' gain below measures heights alone
            move = np.stack([across[..., 0], zero, across[..., 1]], axis=-1)
            rot, hips_pos, mats = _move_feet(sk, tgt, rot, hips_pos, mats, legs, move,
                                             blend, mapped)
            y = vertex_heights(soles, sk, mats)
            low = sole_heights(soles, sk, mats, y) - soles.floor
        if np.abs(goal - low).max() <= tol:
            if slide:
                continue
            break
        change = (goal - low) / gain
        rot, hips_pos, mats = _move_feet(sk, tgt, rot, hips_pos, mats, legs,
                                         np.stack([zero, change, zero], axis=-1), blend,
                                         mapped)
        y = vertex_heights(soles, sk, mats)
        before, low = low, sole_heights(soles, sk, mats, y) - soles.floor
        # how far the sole moved per unit the ankle did (under 1 where the knee's bone
        # carries part of the sole, over 1 where its turn swings a long foot): the next
        # round divides by it, a secant step per frame and foot
        moved = np.abs(change) > tol
        gain = np.where(moved, np.clip((low - before) / np.where(moved, change, 1.0),
                                       0.3, 3.0), gain)
    off = (np.abs(goal - low) > 1e-3 * tgt.hip_height).any(axis=1)
    if off.any():  # the rounds ran out: say so, not silently
        warnings.warn(f"{what}: the skinned soles stay up to {1000 * np.abs(goal - low).max():.1f}"
                      f" mm off where they should stand in {int(off.sum())} of {len(times)} "
                      f"frames (the feet's skin does not follow the ankles)", stacklevel=2)
    return rot, hips_pos, mats


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
