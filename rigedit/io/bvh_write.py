"""BVH out: a rig's skeleton and one clip, sampled at the clip's key rate.

BVH has no rest rotations, no scale and no bind pose: a joint's local transform is
``T(offset or position channels) · R(rotation channels)``. So the writer does not copy the
rig's local values; it takes the model-space joint matrices of every frame (whatever made
them: rest rotations, translation or scale keys, glTF bind poses) and writes the local
rotation and translation that reproduce each joint's model-space position and orientation:

    R_j = rotation of M_j (nearest rotation when scale is present)
    rotation channels of j = R_parent^T R_j            (``Zrotation Xrotation Yrotation``)
    local translation of j = R_parent^T (p_j - p_parent)

OFFSETs come from the rest pose the same way; a joint gets position channels when it is a
root or when its local translation moves away from its offset during the clip. Reading the
file back gives the same joint positions per frame. Lengths are written in centimetres by
default (the most common BVH unit, and what most tools expect): rigedit's unit guess reads a
figure of a human's size (1.2-2.2 m, carrier roots left out) back as centimetres, so a round
trip keeps its size; for any other figure the writer warns (:class:`BvhUnitsWarning`) that
it must be read back with ``scale=0.01``.
"""
from __future__ import annotations

import re
import warnings

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import RigFileError
from ..model.carrier import carrier_joints
from ..model.kinematics import local_to_model
from ..model.pose import Pose
from .atomic import atomic_write
from .bvh_units import HUMAN_SIZE, BvhUnitsWarning, believable
from .data import as_rig_data

__all__ = ["write_bvh", "save_bvh", "bvh_frame_times", "DEFAULT_FPS"]

#: Frame rate used when a clip's keys are not on a regular grid.
DEFAULT_FPS = 30.0
_AXES = "XYZ"


#: Frames a second above which keys on one grid are not taken for the clip's rate.
MAX_KEY_RATE = 1000.0


def bvh_frame_times(clip, fps=None):
    """Sample times for writing ``clip``: its key rate when every key lies on one regular grid
    of step ``dt`` from time 0 and that rate is at most :data:`MAX_KEY_RATE` (divided down to
    30 fps or finer when the clip has bezier tracks, whose curves bend between keys), else
    ``fps`` (default 30) frames per second.

    Returns
    -------
    times : (F,) float64
        ``k * dt`` for k = 0 .. round(duration / dt).
    dt : float
    """
    if clip is None:
        return np.zeros(1), 1.0 / (fps or DEFAULT_FPS)
    if fps is None:
        keys = np.unique(np.concatenate([tr.times for tr in clip.tracks.values()] or [[0.0]]))
        dt = 1.0 / DEFAULT_FPS
        if len(keys) >= 2:
            step = float(np.min(np.diff(keys)))
            grid = keys / step
            # a grid finer than MAX_KEY_RATE is two keys nudged together (a graph drag
            # stopped at its neighbour), not a capture rate: 10,000 frames a second of BVH
            if step >= 1.0 / MAX_KEY_RATE and np.allclose(grid, np.round(grid), atol=1e-4):
                dt = step
                if any(tr.curves is not None for tr in clip.tracks.values()):
                    # bezier curves bend between keys: the grid divided to 30 fps or finer
                    dt = step / np.ceil(step * DEFAULT_FPS - 1e-9)
    else:
        dt = 1.0 / float(fps)
    count = int(round(clip.duration / dt)) + 1 if clip.duration > 0 else 1
    return np.arange(count) * dt, dt


class BvhFramesWarning(UserWarning):
    """A clip's keys are on no frame rate BVH can hold: they are sampled at the frames."""


def _warn_keys_between_frames(clip, times, dt, path):
    """Say so, in one warning, when the frame rate :func:`bvh_frame_times` fell back to leaves
    key times between frames (a BVH holds frames, not keys: those keys are sampled)."""
    if clip is None or not clip.tracks:
        return
    keys = np.unique(np.concatenate([tr.times for tr in clip.tracks.values()]))
    k = np.clip(np.round(keys / dt), 0, len(times) - 1).astype(int)
    off = np.abs(times[k] - keys) > 1e-4 * dt
    if off.any():
        warnings.warn(f"{path}: {int(off.sum())} of {len(keys)} key times fall between the "
                      f"{1 / dt:g} fps frames written (the keys are on no regular grid of at "
                      f"most {MAX_KEY_RATE:g} fps); the clip is sampled there, those keys are "
                      f"not kept as keys (save_bvh's fps= chooses the rate)", BvhFramesWarning)


def _model_frames(skeleton, clip, times):
    """(F, J, 4, 4) model matrices of the clip at ``times`` (the rest pose when no clip)."""
    if clip is None:
        return local_to_model(skeleton, Pose(skeleton))[None]
    return np.stack([local_to_model(skeleton, clip.sample(t)) for t in times])


def _local_parts(model, parents):
    """Local rotations (..., J) Rotation-ready matrices and translations that reproduce
    the positions of ``model`` (..., J, 4, 4) joint by joint."""
    lin = model[..., :3, :3]
    # nearest rotation of each (possibly scaled) matrix
    u, _, vt = np.linalg.svd(lin)
    d = np.sign(np.linalg.det(u @ vt))
    u[..., :, 2] *= d[..., None]
    rot = u @ vt
    pos = model[..., :3, 3]
    local_rot = rot.copy()
    local_t = pos.copy()
    child = np.flatnonzero(parents >= 0)
    par = parents[child]
    rp_t = np.swapaxes(rot[..., par, :, :], -1, -2)
    local_rot[..., child, :, :] = rp_t @ rot[..., child, :, :]
    local_t[..., child, :] = (rp_t @ (pos[..., child, :] - pos[..., par, :])[..., None])[..., 0]
    return local_rot, local_t, rot, pos


def _depth_first(parents):
    children = {j: [] for j in range(-1, len(parents))}
    for j, p in enumerate(parents):
        children[int(p)].append(j)
    order, stack = [], list(reversed(children[-1]))
    while stack:
        j = stack.pop()
        order.append(j)
        stack.extend(reversed(children[j]))
    return order, children


def _bvh_names(names):
    out, seen = [], set()
    for name in names:
        base = re.sub(r"[\s{}]+", "_", name) or "joint"
        new, k = base, 1
        while new in seen:
            k += 1
            new = f"{base}_{k}"
        seen.add(new)
        out.append(new)
    return out


def _warn_unless_human(positions, parents, units_per_metre, path):
    """Warn when the figure in ``positions`` (F, J, 3) metres, carrier roots left out, is
    not a human's size: reading the file back will not guess its unit (BVH has none)."""
    picks = positions[np.unique(np.linspace(0, len(positions) - 1, 32).round().astype(int))]
    carriers = carrier_joints(parents, picks)
    size = float(np.percentile(np.ptp(picks[:, ~carriers], axis=1).max(axis=1), 90))
    if not believable(size):
        warnings.warn(f"{path}: the figure is {size:.3g} m across, not a human's "
                      f"{HUMAN_SIZE[0]:g}-{HUMAN_SIZE[1]:g} m: read it back with scale="
                      f"{1 / units_per_metre:g} (BVH has no units; a guess may differ)",
                      BvhUnitsWarning, stacklevel=3)


def save_bvh(rig, path, clip=None, fps=None, units_per_metre=100.0, order=None):
    """Write ``rig``'s skeleton and one clip as a BVH file, atomically.

    Parameters
    ----------
    rig : RigData or Rig
        The rig's data (:class:`~rigedit.io.data.RigData`; a Rig gives its ``data()``).
    path : str or os.PathLike
    clip : Clip or str, optional
        The clip to write; the rig's first clip when omitted, the rest pose (one frame)
        when the rig has none.
    fps : float, optional
        Frame rate; the clip's key rate when its keys lie on a regular grid, else 30.
    units_per_metre : float
        File units per metre (100: centimetres).
    order : str, optional
        Rotation channel order of every joint, three of ``XYZ`` (``ZXY`` writes ``Zrotation
        Xrotation Yrotation``); by default each joint keeps the order of the BVH file the rig
        was read from (``meta.rotation_orders``), others get ``ZXY``.

    Returns
    -------
    info : dict
        ``clip`` (name or None), ``frames``, ``frame_time``.
    """
    rig = as_rig_data(rig)
    clip = _chosen_clip(rig, clip, path)
    sk = rig.skeleton
    orders = _orders(sk.names, rig.meta.rotation_orders if order is None else {}, order)
    times, dt = bvh_frame_times(clip, fps)
    if fps is None:
        _warn_keys_between_frames(clip, times, dt, path)
    local_rot, local_t, _, frame_pos = _local_parts(_model_frames(sk, clip, times),
                                                    sk.parents)
    _warn_unless_human(frame_pos, sk.parents, float(units_per_metre), path)
    rest_model = local_to_model(sk, Pose(sk))
    _, offsets, rest_rot, rest_pos = _local_parts(rest_model, sk.parents)
    size = float(np.ptp(np.vstack([rest_pos, local_t[:, 0]]), axis=0).max()) or 1.0
    moves = np.abs(local_t - offsets[None]).max(axis=(0, 2)) > 1e-9 * size
    s = float(units_per_metre)
    lines, columns = _hierarchy(_bvh_names(sk.names), sk.parents, orders,
                                (sk.parents < 0) | moves, offsets * s,
                                _end_sites(sk, rest_model, rest_rot, rest_pos) * s,
                                local_t * s, _euler(local_rot, orders))
    lines += ["MOTION", f"Frames: {len(times)}", f"Frame Time: {dt:.10g}"]
    data = np.concatenate(columns, axis=1)
    with atomic_write(path) as fh:
        fh.write("\n".join(lines) + "\n")
        np.savetxt(fh, data, fmt="%.6f")
    return {"clip": None if clip is None else clip.name, "frames": len(times),
            "frame_time": dt}


def _chosen_clip(rig, clip, path):
    """The Clip to write: ``clip`` (a Clip or a clip name), else the rig's first, else None."""
    if isinstance(clip, str):
        if clip not in rig.clips:
            raise RigFileError(path, f"expected a clip of the rig, got {clip!r}")
        clip = rig.clips[clip]
    if clip is None and rig.clips:
        clip = next(iter(rig.clips.values()))
    return clip


def _orders(names, source, order):
    """Each joint's rotation order: the source file's, else ``order``, else ``ZXY``."""
    orders = [str(source.get(name, order or "ZXY")).upper() for name in names]
    for o in set(orders):
        if sorted(o) != ["X", "Y", "Z"]:
            raise ValueError(f"expected a rotation order of X, Y and Z, got {o!r}")
    return orders


def _euler(local_rot, orders):
    """(F, J, 3) degrees: the (F, J, 3, 3) local rotations as each joint's Euler angles."""
    frames, joints = local_rot.shape[:2]
    euler = np.empty((frames, joints, 3))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # gimbal lock: angles still reproduce R
        for o in set(orders):   # one batched conversion per order
            js = [j for j in range(joints) if orders[j] == o]
            euler[:, js] = Rotation.from_matrix(local_rot[:, js].reshape(-1, 3, 3)).as_euler(
                o, degrees=True).reshape(frames, len(js), 3)
    return euler


def _end_sites(sk, rest_model, rest_rot, rest_pos):
    """(J, 3) each joint's End Site offset in its rest frame (metres): its bone tail, zero
    where it has none."""
    ends = np.zeros((len(sk), 3))
    for j in np.flatnonzero(np.all(np.isfinite(sk.tails), axis=1)):
        tail = rest_model[j] @ sk.inverse_bind_matrices[j] @ np.r_[sk.tails[j], 1.0]
        ends[j] = rest_rot[j].T @ (tail[:3] - rest_pos[j])
    return ends


def _hierarchy(names, parents, orders, with_pos, offsets, ends, translations, euler):
    """The HIERARCHY lines and the motion's columns in channel order.

    Parameters
    ----------
    names : list[str]
        BVH-safe joint names.
    parents : (J,) int
    orders : list[str]
        Rotation order of each joint.
    with_pos : (J,) bool
        Joints written with position channels.
    offsets, ends : (J, 3) float
        OFFSETs and End Site offsets, file units.
    translations : (F, J, 3) float
        Local translations per frame, file units.
    euler : (F, J, 3) float
        Degrees per frame.
    """
    order_dfs, children = _depth_first(parents)
    lines, columns = ["HIERARCHY"], []

    def open_joint(j, pad):
        kind = "ROOT" if parents[j] < 0 else "JOINT"
        o = offsets[j]
        chans = (("Xposition Yposition Zposition " if with_pos[j] else "")
                 + " ".join(f"{a}rotation" for a in orders[j]))
        lines.extend([f"{pad}{kind} {names[j]}", f"{pad}{{",
                      f"{pad}  OFFSET {o[0]:.6f} {o[1]:.6f} {o[2]:.6f}",
                      f"{pad}  CHANNELS {6 if with_pos[j] else 3} {chans}"])
        if with_pos[j]:
            columns.append(translations[:, j])
        columns.append(euler[:, j])
        if not children[j]:
            end = ends[j]
            lines.extend([f"{pad}  End Site", f"{pad}  {{",
                          f"{pad}    OFFSET {end[0]:.6f} {end[1]:.6f} {end[2]:.6f}",
                          f"{pad}  }}"])

    # an explicit stack, not recursion: a chain of thousands of joints (from a glTF or a
    # rig folder) is written like any other
    stack = [(j, 0, False) for j in reversed(order_dfs) if parents[j] < 0]
    while stack:
        j, depth, done = stack.pop()
        pad = "  " * depth
        if done:
            lines.append(f"{pad}}}")
            continue
        open_joint(j, pad)
        stack.append((j, depth, True))
        stack.extend((c, depth + 1, False) for c in reversed(children[j]))
    return lines, columns


def write_bvh(data, path, clips=None):
    """The registry's writer (:mod:`rigedit.io.registry`): :func:`save_bvh` of one clip, the
    first named in ``clips`` or the rig's first; more than one is refused."""
    if clips is not None and len(clips) > 1:
        raise RigFileError(path, f"expected one clip for a BVH file, got {len(clips)}")
    return save_bvh(data, path, clip=data.clips[clips[0]] if clips else None)
