"""FBX out: every clip as an animation stack.

A clip becomes an ``AnimationStack`` (its time span 0 to the clip's duration) with one
``AnimationLayer``; each track of a joint becomes an ``AnimationCurveNode`` (``T``, ``R`` or
``S``) on the joint's ``Lcl Translation``, ``Lcl Rotation`` or ``Lcl Scaling`` with three
``AnimationCurve`` children (``d|X``, ``d|Y``, ``d|Z``): key times in FBX ticks
(:data:`~rigedit.io.fbx_document.TICKS_PER_SECOND`), float values, and one interpolation flag
for all keys (linear, or constant for a ``step`` track). Joints without a track keep their
rest transform (the models' static ``Lcl`` values). A morph weight track is a curve node on
its blend shape channel's ``DeformPercent`` (the weight times 100).

FBX curves are per Euler angle and interpolate each one linearly, which is not a slerp of
quaternions (nor a spline), so a track is sampled rather than copied: at its own keys and at
every frame of the scene's rate (:data:`FPS`), so that rigedit and the file agree exactly at
every frame, and rotations also wherever the angles' straight line strays more than
:data:`EULER_TOLERANCE` from the track between keys (:func:`rotation_keys`), so that they
agree closely between. A ``step`` track, and a translation or scale track of ``linear``
keys, is the same curve in FBX and is written at its keys only. Rotations are Euler XYZ degrees
(matrix Rz·Ry·Rx, FBX's ``eEulerXYZ``) made continuous from key to key (each key the
equivalent triple nearest the one before), since FBX interpolates the numbers as written.
"""
from __future__ import annotations

import numpy as np

from ..model.transforms import euler_to_quat
from .fbx_document import TICKS_PER_SECOND, properties70, ticks
from .fbx_write_skin import euler_degrees

__all__ = ["write_clips", "continuous_euler", "sample_times", "rotation_keys",
           "sample_rotations", "FPS", "EULER_TOLERANCE", "MAX_HALVINGS"]

#: The scene's frame rate: every track is keyed at least at each of its frames.
FPS = 30.0
#: Largest angle (degrees) between a rotation track and FBX's interpolation of the written
#: keys, at the middle of each key interval: 2e-4 degrees moves a point 1 m from the joint by
#: 3.5 micrometres.
EULER_TOLERANCE = 2e-4
#: At most this many halvings of a key interval (1/30 s -> about 8 microseconds).
MAX_HALVINGS = 12
_CURVE_NODE = {"translation": ("T", "Lcl Translation"), "rotation": ("R", "Lcl Rotation"),
               "scale": ("S", "Lcl Scaling")}
# KeyAttrFlags (FbxAnimCurveDef): eInterpolationConstant 0x2, eInterpolationLinear 0x4
_LINEAR, _CONSTANT = 0x4, 0x2


def _wrap(degrees):
    """Angles into [-180, 180)."""
    return (degrees + 180.0) % 360.0 - 180.0


def continuous_euler(quats):
    """(T, 4) quaternions -> (T, 3) Euler XYZ degrees, each row the equivalent triple nearest
    the row before (so linear interpolation between rows takes the short way).

    Each rotation has two XYZ triples up to whole turns, ``(a, b, c)`` and ``(a + 180,
    180 - b, c + 180)``; the choice of the twin at row ``i`` is relative to row ``i - 1``'s,
    and the distance from a triple to the twin of another equals the distance from its twin to
    that one, so the parities are a cumulative xor of neighbour comparisons, and the whole
    turns a cumulative sum of wrapped differences: no Python loop over the keys.
    """
    e = euler_degrees(quats)
    if len(e) < 2:
        return e
    twin = np.column_stack([e[:, 0] + 180.0, 180.0 - e[:, 1], e[:, 2] + 180.0])
    same = np.abs(_wrap(e[1:] - e[:-1])).sum(axis=1)
    cross = np.abs(_wrap(twin[1:] - e[:-1])).sum(axis=1)
    parity = np.concatenate([[False], np.logical_xor.accumulate(cross < same)])
    chosen = np.where(parity[:, None], twin, e)
    chosen[0] = e[0]
    steps = _wrap(np.diff(chosen, axis=0))
    return np.vstack([chosen[:1], chosen[0] + np.cumsum(steps, axis=0)])


def sample_times(track, duration, fps=FPS):
    """(N,) times a track is written at, seconds: its keys within ``[0, duration]``, both
    ends, and every frame when FBX's linear curve is not the track's own (rotations, splines);
    no two in the same tick."""
    # FBX's constant keys are a step track exactly, its linear keys a linear vector track
    exact = track.interpolation == "step" or (track.channel != "rotation"
                                              and track.interpolation == "linear")
    return _times(track.times, duration, exact, fps)


def _times(keys, duration, exact, fps=FPS):
    times = [keys[(keys >= 0) & (keys <= duration)], [0.0, duration]]
    if not exact:
        times.append(np.arange(int(np.floor(duration * fps + 1e-9)) + 1) / fps)
    t = np.unique(np.concatenate(times))
    _, first = np.unique(np.round(t * TICKS_PER_SECOND).astype(np.int64), return_index=True)
    return t[first]


def _curves(scene, node_id, times, values, step, names="XYZ"):
    """The curves of a curve node, one per name (``d|X``...): key times ``times`` (N,),
    values (N, len(names)), constant interpolation when ``step``, else linear."""
    key_time = np.array([ticks(t) for t in times], dtype=np.int64)
    flag = _CONSTANT if step else _LINEAR
    for axis, name in enumerate(names):
        uid, curve = scene.add("AnimationCurve", "", "AnimCurve")
        column = np.asarray(values[:, axis], dtype=np.float32)
        curve.add("Default", float(column[0]))
        curve.add("KeyVer", 4008)
        curve.add("KeyTime", key_time)
        curve.add("KeyValueFloat", column)
        curve.add("KeyAttrFlags", np.array([flag], np.int32))
        curve.add("KeyAttrDataFloat", np.zeros(4, np.float32))
        curve.add("KeyAttrRefCount", np.array([len(times)], np.int32))
        scene.connect(uid, node_id, f"d|{name}")


def sample_rotations(track, times):
    """(N, 4) values of a rotation track at ``times`` (N,): ``track.sample`` at each, with
    slerp and nlerp tracks (most of a file's) done for all times at once, the same formulas
    as :mod:`rigedit.animation.interpolate` (an export samples a track thousands of times)."""
    times = np.asarray(times, dtype=np.float64).reshape(-1)
    if track.interpolation not in ("slerp", "nlerp"):
        return track.sample_many(times).reshape(-1, 4)   # every mode in one vectorised call
    keys, values = track.times, track.values
    i = np.clip(np.searchsorted(keys, times, side="right") - 1, 0, len(keys) - 1)
    k = np.minimum(i + 1, len(keys) - 1)
    span = np.where(k > i, keys[k] - keys[i], 1.0)
    u = np.clip(np.where(k > i, (times - keys[i]) / span, 0.0), 0.0, 1.0)[:, None]
    a, b = values[i], values[k]
    dot = np.sum(a * b, axis=1)
    b = np.where(dot[:, None] < 0, -b, b)        # the shortest way (keys are aligned already)
    dot = np.abs(dot)
    near = a + (b - a) * u
    near /= np.linalg.norm(near, axis=1, keepdims=True)
    if track.interpolation == "nlerp":
        return near
    theta = np.arccos(np.minimum(dot, 1.0))[:, None]
    sin = np.where(theta > 0, np.sin(theta), 1.0)
    far = (np.sin((1 - u) * theta) * a + np.sin(u * theta) * b) / sin
    # nearly parallel keys: nlerp, as interpolate.slerp does (the sine ratio is ill-conditioned)
    return np.where((dot > 1.0 - 1e-10)[:, None], near, far)


def rotation_keys(track, duration, tolerance=EULER_TOLERANCE):
    """Key times and continuous Euler XYZ degrees of a rotation track such that FBX's
    linear interpolation of the angles stays within ``tolerance`` degrees of the track.

    Starts from :func:`sample_times` and halves every interval whose middle is further than
    ``tolerance`` from the track (an angle between rotations), checking only the new halves
    again, at most :data:`MAX_HALVINGS` times. Needed where the angles move fast though the
    rotation does not (near gimbal lock, the middle angle near +-90 degrees, the first and
    third swing together) and where a key interval turns far (a slerp of 100 degrees in one
    frame is not a straight line in angles).

    Returns
    -------
    times : (N,) float64
    degrees : (N, 3) float64
    """
    t = sample_times(track, duration)
    q = sample_rotations(track, t)
    # a step track is written with constant keys: nothing in between to follow
    check = np.full(max(len(t) - 1, 0), track.interpolation != "step")
    for _ in range(MAX_HALVINGS):
        idx = np.flatnonzero(check)
        if not len(idx):
            break
        e = continuous_euler(q)
        middle = 0.5 * (t[idx] + t[idx + 1])
        linear = euler_to_quat(0.5 * (e[idx] + e[idx + 1]), degrees=True)
        true = sample_rotations(track, middle)
        cos = np.clip(np.abs(np.sum(linear * true, axis=1)), 0.0, 1.0)
        bad = np.degrees(2.0 * np.arccos(cos)) > tolerance
        if not bad.any():
            break
        split = idx[bad]
        t = np.insert(t, split + 1, middle[bad])
        q = np.insert(q, split + 1, true[bad], axis=0)
        check = np.zeros(len(t) - 1, dtype=bool)
        first = split + np.arange(len(split))          # the first half's index after inserting
        check[first] = check[first + 1] = True
    return t, continuous_euler(q)


def _track(scene, layer, model, track, duration, unit):
    if track.channel == "rotation":
        times, values = rotation_keys(track, duration)
    else:
        times = sample_times(track, duration)
        values = np.array([track.sample(t) for t in times])
    if track.channel == "translation":
        values = values * unit
    short, prop = _CURVE_NODE[track.channel]
    uid, node = scene.add("AnimationCurveNode", short, "AnimCurveNode")
    node.append(properties70(*((f"d|{a}", "number", float(values[0, k]))
                               for k, a in enumerate("XYZ"))))
    scene.connect(uid, layer)
    scene.connect(uid, model, prop)
    _curves(scene, uid, times, values, track.interpolation == "step")


def _weight_track(scene, layer, channel, track, duration):
    """A morph weight track as its channel's ``DeformPercent`` curve (weight x 100)."""
    times = _times(track.times, duration, exact=track.interpolation in ("LINEAR", "STEP"))
    values = np.array([[track.sample(t) * 100.0] for t in times])
    uid, node = scene.add("AnimationCurveNode", "DeformPercent", "AnimCurveNode")
    node.append(properties70(("d|DeformPercent", "number", float(values[0, 0]))))
    scene.connect(uid, layer)
    scene.connect(uid, channel, "DeformPercent")
    _curves(scene, uid, times, values, track.interpolation == "STEP", names=("DeformPercent",))


def write_clips(scene, clips, joint_ids, skeleton, unit, channels=None):
    """An animation stack per clip.

    Parameters
    ----------
    scene : rigedit.io.fbx_document.Scene
    clips : list[rigedit.animation.clip.Clip]
    joint_ids : list[Int64]
        Model id of each joint of ``skeleton``.
    skeleton : rigedit.model.skeleton.Skeleton
    unit : float
        File units per metre.
    channels : dict[str, Int64], optional
        Morph target name -> blend shape channel id; a clip's weight tracks of targets not
        in it (a clip made for another mesh) are not written.
    """
    channels = channels or {}
    for clip in clips:
        duration = float(clip.duration)
        stack, node = scene.add("AnimationStack", clip.name, "AnimStack")
        span = (ticks(0), ticks(duration))
        node.append(properties70(("LocalStart", "time", span[0]), ("LocalStop", "time", span[1]),
                                 ("ReferenceStart", "time", span[0]),
                                 ("ReferenceStop", "time", span[1])))
        layer, _ = scene.add("AnimationLayer", "BaseLayer", "AnimLayer")
        scene.connect(layer, stack)
        scene.takes.append((clip.name, duration))
        for (joint, _channel), track in clip.tracks.items():
            _track(scene, layer, joint_ids[skeleton.index[joint]], track, duration, unit)
        for target, track in getattr(clip, "morph_tracks", {}).items():
            if target in channels:
                _weight_track(scene, layer, channels[target], track, duration)
