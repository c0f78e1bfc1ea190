"""BVH motion capture (Biovision hierarchy): a skeleton and one clip, no mesh.

What rigedit reads, precisely:

- ``HIERARCHY``: one or more ``ROOT`` blocks of nested ``JOINT`` blocks, each with an
  ``OFFSET x y z`` and a ``CHANNELS n name...`` line, and ``End Site { OFFSET }`` blocks.
  Joints are stored in the file's depth-first order (parent before child).
- A joint's local transform at a frame is ``T(t) · R``: ``t`` is its OFFSET with each
  component that has a position channel *replaced* by that channel's value (the reading of
  Autodesk's and of most mocap tools; Bandai's files, whose every joint has position channels
  equal to its offset, are only right under it), applied in the parent's frame; ``R`` is the
  product of the rotation channels *in the order listed* (``Zrotation Xrotation Yrotation``
  gives ``Rz · Rx · Ry``: intrinsic rotations), angles in degrees.
- An ``End Site`` gives its joint's tail (``Skeleton.tails``, model space at rest); a
  zero-length one gives none.
- ``MOTION``: ``Frames: N``, ``Frame Time: dt`` (seconds, > 0), then N lines of numbers, one
  per channel in the order the channels appear in the hierarchy.

The clip (named ``take``) has one key per frame at ``k * dt``: a rotation track (``slerp``)
for every joint with a rotation channel, a translation track (``linear``) for every joint
with a position channel. It does not loop. The rest pose is the OFFSETs with no rotation.

Carrier roots (:mod:`rigedit.model.carrier`: a root above the hips that only carries the
figure, Bandai's ``joint_Root``, iClone's ``RL_BoneRoot``) are found on frames sampled over
the clip; they deform nothing (``Skeleton.deform``), ``meta.notes["carrier"]`` names them,
and the figure's size leaves them out.

Units: BVH has none. ``scale`` (metres per file unit) converts; when it is omitted the unit
is guessed from the figure's size (its largest extent over sampled frames, 90th percentile,
carrier roots left out; see :func:`rigedit.io.bvh_units.guess_unit`): the unit that makes
it a human's 1.2-2.2 m, else the nearest, NOT SURE. The guess is reported in a :class:`BvhUnitsWarning`
and in ``meta.notes["units"]``. Frames: BVH is conventionally Y up, rigedit's own convention,
so axes are kept as they are (``meta.notes["frames"]`` says so).
"""
from __future__ import annotations

import warnings
from collections import Counter
from pathlib import Path

import numpy as np

from ..animation.clip import Clip, Track
from ..errors import RigFileError
from ..model.carrier import carrier_joints, carrier_note
from ..model.skeleton import Skeleton
from ..model.transforms import compose_trs, quat_multiply
from .bvh_parse import parse_bvh
from .bvh_units import (HUMAN_SIZE, TYPICAL_HEIGHT, UNITS, BvhUnitsWarning, believable,
                        guess_unit)
from .bvh_write import save_bvh as _save_bvh
from .data import RigData, RigMeta, build_rig

__all__ = ["read_bvh", "load_bvh", "save_bvh", "parse_bvh", "guess_unit", "believable",
           "euler_channels_to_quats", "BvhUnitsWarning", "UNITS", "HUMAN_SIZE",
           "TYPICAL_HEIGHT", "CLIP_NAME"]

CLIP_NAME = "take"
#: Bound on a figure's lengths in metres (offsets, End Sites, position channels, times the
#: scale): a thousand kilometres. Written back as BVH in millimetres it stays within the
#: reader's bound on file values (:data:`rigedit.io.bvh_parse.MAX_VALUE`), so whatever is
#: read can be exported and read again, and float32 skinning is far from overflow.
MAX_METRES = 1e6
#: Frames looked at, evenly spaced, to find carrier roots and to measure the figure.
SAMPLED_FRAMES = 32


def _axis_quats(axis, sin_half, cos_half):
    """(N, 4) quaternions (x, y, z, w) of rotations about axis 0, 1 or 2, from the sine and
    cosine of the half angles."""
    q = np.zeros((len(sin_half), 4))
    q[:, axis] = sin_half
    q[:, 3] = cos_half
    return q


def _compose(sin_half, cos_half, axes):
    q = _axis_quats(axes[0], sin_half[:, 0], cos_half[:, 0])
    for k in range(1, len(axes)):
        q = quat_multiply(q, _axis_quats(axes[k], sin_half[:, k], cos_half[:, k]))
    return q


def euler_channels_to_quats(angles, axes):
    """Quaternions of BVH rotation channels: the product of the axis rotations in order.

    Parameters
    ----------
    angles : (N, K) float
        Degrees, one column per rotation channel, in the order listed (K = 1-3 or more).
    axes : sequence of int
        The axis of each column (0 = X, 1 = Y, 2 = Z).

    Returns
    -------
    quats : (N, 4) float64, (x, y, z, w); equal to ``Rotation.from_euler(seq, angles,
    degrees=True)`` with ``seq`` the upper-case (intrinsic) axis letters.

    Notes
    -----
    Written out rather than calling SciPy because ``Rotation.from_euler`` measured about
    1.7 us per rotation here (SciPy 1.17): 0.5 s for 10,000 frames of 31 joints, the whole
    budget of a BVH load; this is one vectorised product per channel
    (:func:`rigedit.model.transforms.quat_multiply`).
    """
    half = np.radians(np.asarray(angles, dtype=np.float64)) * 0.5
    return _compose(np.sin(half), np.cos(half), list(axes))


def _channel_values(data):
    """Per-joint rotation quaternions (N, 4) and local translations (N, 3) in file units:
    ``{joint index: array}`` for the joints that have such channels."""
    frames, offsets = data["frames"], data["offsets"]
    # the sines and cosines of every channel's half angle in two calls, not one per joint
    half = np.radians(frames) * 0.5
    sin_half, cos_half = np.sin(half), np.cos(half)
    rotations, translations = {}, {}
    col = 0
    for j, channels in enumerate(data["channels"]):
        rot = [(axis, col + k) for k, (kind, axis) in enumerate(channels) if kind == "rotation"]
        if rot:
            cols = [c for _, c in rot]
            rotations[j] = _compose(sin_half[:, cols], cos_half[:, cols], [a for a, _ in rot])
        pos = [(axis, col + k) for k, (kind, axis) in enumerate(channels) if kind == "position"]
        if pos:
            values = np.repeat(offsets[j][None], len(frames), axis=0)
            for axis, c in pos:  # replaces the OFFSET component (module notes)
                values[:, axis] = frames[:, c]
            translations[j] = values
        col += len(channels)
    return rotations, translations


def _sampled_poses(data, rotations, translations):
    """Model-space joints (P, J, 3) and End Site points (P, T, 3), file units, at up to
    :data:`SAMPLED_FRAMES` frames spread over the clip (frame 0 first), or at rest when the
    file has no frames; and the End Sites' joints (T,)."""
    offsets, ends, frames = data["offsets"], data["ends"], data["frames"]
    sk = Skeleton(data["names"], data["parents"], offsets)
    picks = np.unique(np.linspace(0, len(frames) - 1, SAMPLED_FRAMES).round().astype(int)) \
        if len(frames) else [None]
    owners = [j for j, e in enumerate(ends) if e is not None]
    local_ends = np.array([ends[j] for j in owners]).reshape(-1, 3)
    heads, tips = [], []
    for f in picks:
        pose_t, pose_r = offsets.copy(), sk.rest_rotation.copy()
        if f is not None:
            for j, q in rotations.items():
                pose_r[j] = q[f]
            for j, t in translations.items():
                pose_t[j] = t[f]
        model = sk.forward(compose_trs(pose_t, pose_r))
        heads.append(model[:, :3, 3])
        tips.append(np.einsum("tij,tj->ti", model[owners, :3, :3], local_ends)
                    + model[owners, :3, 3])
    return np.array(heads), np.array(tips).reshape(len(heads), -1, 3), np.array(owners, int)


def _figure_size(heads, tips, owners, carriers):
    """The figure's largest extent (file units): its joints and End Sites, carrier roots
    left out, in each sampled pose; the 90th percentile over the poses, so that a crouch at
    frame 0 or a run's lean does not shrink it and one glitched frame does not grow it."""
    keep = np.flatnonzero(~carriers)
    points = np.concatenate([heads[:, keep], tips[:, ~carriers[owners]]], axis=1)
    return float(np.percentile(np.max(np.ptp(points, axis=1), axis=1), 90))


def _units(path, size, measured, scale):
    """The scale (metres per unit) and what was decided: ``(scale, unit name or None,
    guessed, note)``; the unit is guessed from the figure's ``size`` (file units) when
    ``scale`` is None, and the guess is warned about."""
    if scale is not None:
        scale = float(scale)
        if not np.isfinite(scale) or scale <= 0:
            raise RigFileError(path, f"expected a scale > 0 (metres per unit), got {scale}")
        return scale, None, False, (f"scale {scale:g} m per unit (given): "
                                    f"{size * scale:.3g} m across")
    unit, scale = guess_unit(size)
    note = (f"guessed {unit} from the figure's size ({measured}): "
            f"{size * scale:.3g} m, scale {scale:g} m per unit")
    if not believable(size * scale):
        note += (f"; NOT SURE: no unit makes it a human's {HUMAN_SIZE[0]:g}-"
                 f"{HUMAN_SIZE[1]:g} m (not a human, or an unusual unit)")
    warnings.warn(f"{path}: BVH has no units; {note}; pass --scale/scale= to override",
                  BvhUnitsWarning, stacklevel=3)
    return scale, unit, True, note


def _check_metres(path, data, translations, scale):
    """Refuse lengths beyond :data:`MAX_METRES` once scaled (see there)."""
    ends = [e for e in data["ends"] if e is not None]
    parts = [data["offsets"], *ends, *translations.values()]
    largest = max(float(np.abs(p).max()) if np.size(p) else 0.0 for p in parts) * scale
    if largest > MAX_METRES:
        raise RigFileError(path, f"expected lengths within {MAX_METRES:g} m, got "
                                 f"{largest:.3g} m (at {scale:g} m per unit): a figure that "
                                 "large cannot be skinned or exported")


def _clip(data, skeleton, rotations, translations, scale):
    """``{"take": Clip}`` of the file's frames (one key per frame), {} without frames."""
    if not len(data["frames"]):
        return {}
    names = data["names"]
    times = np.arange(len(data["frames"])) * data["frame_time"]
    tracks = {(names[j], "rotation"): Track("rotation", times, q, "slerp")
              for j, q in rotations.items()}
    tracks.update({(names[j], "translation"): Track("translation", times, t * scale, "linear")
                   for j, t in translations.items()})
    return {CLIP_NAME: Clip(CLIP_NAME, skeleton, tracks, duration=float(times[-1]), loop=False)}


def read_bvh(path, scale=None):
    """Read a BVH file into a mesh-less :class:`~rigedit.io.data.RigData` with one clip (see
    the module notes).

    Parameters
    ----------
    path : str or os.PathLike
    scale : float, optional
        Metres per file unit; when omitted, guessed from the figure's size over the clip,
        carrier roots left out, and reported (NOT SURE when no unit makes it a human's).

    Returns
    -------
    RigData
        ``vertices`` (0, 3), ``faces`` (0, 3), empty (0, 1) influences; ``clips``
        ``{"take": Clip}`` unless the file has no frames; ``meta`` with ``scale``, ``units``
        (the guessed unit, None when given), ``rotation_orders``, and ``notes`` with
        ``units``, ``frames``, ``rotation_order`` and ``carrier`` when the skeleton has
        carrier roots (they are ``deform=False``).
    """
    path = Path(path)
    data = parse_bvh(path)
    offsets, parents, ends = data["offsets"], data["parents"], data["ends"]
    rotations, translations = _channel_values(data)
    names = data["names"]
    heads, tips, owners = _sampled_poses(data, rotations, translations)
    carriers = carrier_joints(parents, heads)
    size = _figure_size(heads, tips, owners, carriers)
    left_out = ", ".join(names[j] for j in np.flatnonzero(carriers))
    measured = f"{size:.4g} units across" + (f", carrier root {left_out} left out"
                                             if left_out else "")
    scale, unit, guessed, units_note = _units(path, size, measured, scale)
    _check_metres(path, data, translations, scale)
    rest = Skeleton(names, parents, offsets).bind_matrices[:, :3, 3]
    tails = np.full_like(rest, np.nan)
    for j, end in enumerate(ends):
        if end is not None and np.any(end != 0):
            tails[j] = (rest[j] + end) * scale
    # a carrier root deforms nothing: its "bone" runs from the floor (or the origin) to
    # the hips
    skeleton = Skeleton(names, parents, offsets * scale, tails=tails, deform=~carriers)
    # each joint's rotation channel order, so that a BVH written back keeps it (bvh_write)
    orders = {name: "".join("XYZ"[axis] for kind, axis in channels if kind == "rotation")
              for name, channels in zip(names, data["channels"])}
    orders = {n: o for n, o in orders.items() if sorted(o) == list("XYZ")}
    notes = {"units": units_note,
             "frames": "BVH read as Y up, +Z forward (its usual convention), axes kept"}
    if carriers.any():
        notes["carrier"] = carrier_note(names, parents, heads, carriers, scale)
    counts = Counter(orders.values()).most_common()
    notes["rotation_order"] = ", ".join(f"{o} ({n} joints)" for o, n in counts) or "-"
    meta = RigMeta(source=path, format="bvh", units=unit, scale=scale, scale_guessed=guessed,
                   rotation_orders=orders, notes=notes)
    return RigData(skeleton, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64),
                   np.zeros((0, 1), dtype=np.int64), np.zeros((0, 1)),
                   _clip(data, skeleton, rotations, translations, scale), name=path.stem,
                   up="y", meta=meta)


def load_bvh(path, scale=None):
    """Read a BVH file into a mesh-less :class:`~rigedit.rig.Rig` with one clip
    (:func:`read_bvh`, then ``Rig.from_data``); ``rig.meta`` and ``rig.notes`` say what was
    decided. Kept for the callers of old: new code reads the data and builds the rig."""
    return build_rig(read_bvh(path, scale=scale))


def save_bvh(rig, path, clip=None, **kwargs):
    """Write ``rig``'s skeleton and one clip as BVH; see :func:`rigedit.io.bvh_write.save_bvh`."""
    return _save_bvh(rig, path, clip=clip, **kwargs)
