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

Units: BVH has none. ``scale`` (metres per file unit) converts; when it is omitted the unit
is guessed from the figure's size at its first frame (see :func:`guess_unit`) and the guess is
reported in a :class:`BvhUnitsWarning` and in ``rig.notes["units"]``. Frames: BVH is
conventionally Y up, rigedit's own convention, so axes are kept as they are
(``rig.notes["frames"]`` says so).
"""
from __future__ import annotations

import warnings
from collections import Counter
from pathlib import Path

import numpy as np

from ..animation.clip import Clip, Track
from ..errors import RigFileError
from ..model.skeleton import Skeleton
from ..model.transforms import compose_trs, quat_multiply
from ..rig import Rig
from .bvh_parse import parse_bvh

__all__ = ["load_bvh", "save_bvh", "parse_bvh", "guess_unit", "euler_channels_to_quats",
           "BvhUnitsWarning", "UNITS", "CLIP_NAME"]

CLIP_NAME = "take"
#: Units a BVH figure may be written in: name -> metres per unit. "CMU" is the unit of the
#: Carnegie Mellon mocap library's BVH conversions (its ASF "length 0.45": 1/0.45 inch).
UNITS = {"metres": 1.0, "centimetres": 0.01, "millimetres": 0.001, "inches": 0.0254,
         "CMU units (1/0.45 inch)": 0.0254 / 0.45}
#: The figure height a guess aims at (an adult human), metres.
TYPICAL_HEIGHT = 1.7


class BvhUnitsWarning(UserWarning):
    """A BVH file's unit was guessed (no ``scale`` given)."""


def _rest_points(parents, offsets, ends):
    """Model-space heads and End Site points at rest (no rotations: offsets add up)."""
    heads = np.zeros_like(offsets)
    for j, p in enumerate(parents):
        heads[j] = offsets[j] + (heads[p] if p >= 0 else 0.0)
    tips = [heads[j] + e for j, e in enumerate(ends) if e is not None]
    return heads, np.array(tips).reshape(-1, 3)


def _deforming(parents, heads, tips):
    """(J,) bool: False for a root that only carries the figure (Bandai's ``joint_Root``): a
    root with one child, at the figure's lowest level, so its "bone" would run from the floor
    up to the hips."""
    deform = np.ones(len(parents), dtype=bool)
    points = np.vstack([heads, tips])
    height = float(np.ptp(points[:, 1])) or 1.0
    for r in np.flatnonzero(parents < 0):
        if (np.sum(parents == r) == 1
                and heads[r, 1] - points[:, 1].min() < 0.05 * height):
            deform[r] = False
    return deform


def guess_unit(size):
    """The unit under which a figure ``size`` file units tall is nearest an adult's height.

    Parameters
    ----------
    size : float
        The largest extent of the figure at rest (height, or arm span in a T pose).

    Returns
    -------
    name : str
    metres_per_unit : float

    Notes
    -----
    The choice minimises ``|log(size * unit / 1.7 m)|`` over :data:`UNITS`: a figure 150-190
    units tall reads as centimetres, 1.5-1.9 as metres, 1500-1900 as millimetres, 55-75 as
    inches, 27-34 as CMU units. A figure that is not human-sized may be misread: pass a scale.
    """
    if not size > 0:
        return "metres", 1.0
    name = min(UNITS, key=lambda u: abs(np.log(size * UNITS[u] / TYPICAL_HEIGHT)))
    return name, UNITS[name]


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


def _figure_size(data, rotations, translations):
    """Largest extent of the figure (joints and End Sites, file units) at frame 0, or at
    rest when the file has no frames: a standing figure's height (or arm span)."""
    offsets, ends = data["offsets"], data["ends"]
    sk = Skeleton(data["names"], data["parents"], offsets)
    pose_t, pose_r = offsets.copy(), sk.rest_rotation.copy()
    if len(data["frames"]):
        for j, q in rotations.items():
            pose_r[j] = q[0]
        for j, t in translations.items():
            pose_t[j] = t[0]
    model = sk.forward(compose_trs(pose_t, pose_r))
    points = [model[:, :3, 3]] + [model[j, :3, :3] @ e + model[j, :3, 3]
                                  for j, e in enumerate(ends) if e is not None]
    points = np.vstack(points)
    return float(np.max(points.max(axis=0) - points.min(axis=0)))


def load_bvh(path, scale=None):
    """Read a BVH file into a mesh-less :class:`Rig` with one clip (see the module notes).

    Parameters
    ----------
    path : str or os.PathLike
    scale : float, optional
        Metres per file unit; guessed from the figure's size at the first frame when
        omitted (and reported).

    Returns
    -------
    Rig
        ``vertices`` (0, 3), ``faces`` (0, 3); ``clips`` ``{"take": Clip}`` unless the file
        has no frames; ``notes`` with ``units`` and ``frames``.
    """
    path = Path(path)
    data = parse_bvh(path)
    offsets, parents, ends = data["offsets"], data["parents"], data["ends"]
    rotations, translations = _channel_values(data)
    if scale is None:
        size = _figure_size(data, rotations, translations)
        unit, scale = guess_unit(size)
        units_note = (f"guessed {unit} from the figure's size ({size:.4g} units at frame 0), "
                      f"scale {scale:g} m per unit; pass --scale/scale= to override")
        warnings.warn(f"{path}: BVH has no units; {units_note}", BvhUnitsWarning, stacklevel=2)
    else:
        scale = float(scale)
        if not np.isfinite(scale) or scale <= 0:
            raise RigFileError(path, f"expected a scale > 0 (metres per unit), got {scale}")
        units_note = f"scale {scale:g} m per unit (given)"
    heads, tips = _rest_points(parents, offsets, ends)
    tails = np.full_like(heads, np.nan)
    for j, end in enumerate(ends):
        if end is not None and np.any(end != 0):
            tails[j] = (heads[j] + end) * scale
    names = data["names"]
    skeleton = Skeleton(names, parents, offsets * scale, tails=tails,
                        deform=_deforming(parents, heads, tips))
    clips = {}
    if len(data["frames"]):
        times = np.arange(len(data["frames"])) * data["frame_time"]
        tracks = {(names[j], "rotation"): Track("rotation", times, q, "slerp")
                  for j, q in rotations.items()}
        tracks.update({(names[j], "translation"): Track("translation", times, t * scale,
                                                        "linear")
                       for j, t in translations.items()})
        clips[CLIP_NAME] = Clip(CLIP_NAME, skeleton, tracks, duration=float(times[-1]),
                                loop=False)
    rig = Rig(skeleton, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64),
              np.zeros((0, 1), dtype=np.int64), np.zeros((0, 1)), clips, name=path.stem,
              up="y", path=path)
    rig.notes = {"units": units_note,
                 "frames": "BVH read as Y up, +Z forward (its usual convention), axes kept"}
    # each joint's rotation channel order, so that a BVH written back keeps it (bvh_write)
    orders = {name: "".join("XYZ"[axis] for kind, axis in channels if kind == "rotation")
              for name, channels in zip(names, data["channels"])}
    rig.source_rotation_orders = {n: o for n, o in orders.items() if sorted(o) == list("XYZ")}
    counts = Counter(rig.source_rotation_orders.values()).most_common()
    rig.notes["rotation_order"] = ", ".join(f"{o} ({n} joints)" for o, n in counts) or "-"
    return rig


def save_bvh(rig, path, clip=None, **kwargs):
    """Write ``rig``'s skeleton and one clip as BVH; see :func:`rigedit.io.bvh_write.save_bvh`."""
    from .bvh_write import save_bvh as _save_bvh

    return _save_bvh(rig, path, clip=clip, **kwargs)
