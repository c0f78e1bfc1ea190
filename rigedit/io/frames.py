"""Frames (axis conventions) at the io boundary: axis changes and the elk layout's guess.

Inside rigedit a character is Y up, +Z forward (glTF's convention). Two kinds of change:

- :func:`change_axes` converts a skeleton *and* its clips together by a rotation ``R`` of the
  model frame: every local transform is conjugated, ``L' = C L C^-1`` with ``C`` the 4x4 of
  ``R`` (translations rotated, rotation keys conjugated, scale keys permuted), bind matrices
  likewise, so a mesh whose vertices are mapped by ``R`` skins to ``R`` times the original
  positions at every frame. That is the change for rigedit's own formats, glTF and BVH.
- The elk layout (``models/*.obj`` + ``skeleton/skeleton.json``) is the exception: Blender's
  OBJ exporter wrote the mesh Y up while the skeleton's heads and tails are Blender world
  coordinates, Z up, and its clips were made for the seed's viewer, which moves only the
  skeleton's *points* into the mesh's frame, ``(x, y, z) -> (x, z, -y)``, and plays the keys
  unchanged there (a pelvis translation along +y is then the vertical bob).
  :func:`resolve_folder_frames` decides which case a folder is in: ``rig.json``'s ``"up"``
  (the mesh) and ``"skeleton_up"`` when stated, else a guess: the convention under which the
  joints lie inside the mesh.
"""
from __future__ import annotations

import warnings

import numpy as np
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from ..animation.clip import Clip, Track
from ..errors import RigFileError
from ..model.skeleton import Skeleton
from ..model.transforms import quat_multiply

__all__ = ["Z_UP_TO_Y_UP", "axis_change", "change_axes", "move_skeleton_points",
           "joints_inside_score", "resolve_folder_frames", "FramesWarning"]

#: (x, y, z) -> (x, z, -y): Blender's Z-up world into a Y-up, -Z-forward export.
Z_UP_TO_Y_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


class FramesWarning(UserWarning):
    """A reader converted a skeleton between axis conventions (says which and why)."""


def axis_change(source_up, target_up):
    """(3, 3) rotation taking points from a ``source_up`` to a ``target_up`` frame ("y"/"z")."""
    if source_up == target_up:
        return np.eye(3)
    if (source_up, target_up) == ("z", "y"):
        return Z_UP_TO_Y_UP.copy()
    if (source_up, target_up) == ("y", "z"):
        return Z_UP_TO_Y_UP.T.copy()
    raise ValueError(f"expected up axes 'y' or 'z', got {source_up!r} and {target_up!r}")


def _change_track(track, R):
    """A track's keys (and spline tangents) in the frame ``R`` takes points to."""
    if track.channel == "rotation":
        r = Rotation.from_matrix(R).as_quat()

        def change(v):
            return _quat_sandwich(r, v)
    else:  # translations rotate; a scale along an axis moves to the axis R takes it to
        M = R if track.channel == "translation" else np.abs(R)

        def change(v):
            return v @ M.T
    tangents = track.tangents if track.interpolation == "cubic_spline" else None
    if tangents is not None:
        tangents = change(tangents.reshape(-1, tangents.shape[-1])).reshape(tangents.shape)
    return Track(track.channel, track.times, change(track.values), track.interpolation,
                 tangents)


def _quat_sandwich(r, q):
    """``r q r^-1`` for (N, 4) quaternions q (x, y, z, w), r a unit quaternion: linear in q
    and sign-preserving (a cubic spline's keys and tangents must keep their signs)."""
    r = np.asarray(r, dtype=np.float64)
    return quat_multiply(quat_multiply(r, q), r * np.array([-1.0, -1.0, -1.0, 1.0]))


def change_axes(skeleton, clips, R):
    """Convert a skeleton and its clips into another frame: model points ``p' = R p``.

    Parameters
    ----------
    skeleton : Skeleton
    clips : dict[str, Clip] or list[Clip]
    R : (3, 3) float
        A rotation (an axis change such as :data:`Z_UP_TO_Y_UP`); every local transform is
        conjugated by it, so model matrices become ``C M C^-1``.

    Returns
    -------
    skeleton : Skeleton
    clips : dict[str, Clip]
        New objects; the inputs are unchanged.
    """
    R = np.asarray(R, dtype=np.float64)
    if R.shape != (3, 3) or not np.allclose(R @ R.T, np.eye(3), atol=1e-9) or \
            np.linalg.det(R) < 0:
        raise ValueError("expected a (3, 3) rotation matrix for the axis change")
    C = np.eye(4)
    C[:3, :3] = R
    sk = skeleton
    new = Skeleton(sk.names, sk.parents, sk.rest_translation @ R.T,
                   _quat_sandwich(Rotation.from_matrix(R).as_quat(), sk.rest_rotation), sk.rest_scale @ np.abs(R).T,
                   bind_matrices=C @ sk.bind_matrices @ C.T, tails=sk.tails @ R.T,
                   deform=sk.deform)
    items = clips.values() if isinstance(clips, dict) else clips
    out = {}
    for clip in items:
        tracks = {key: _change_track(track, R) for key, track in clip.tracks.items()}
        # weight tracks are not spatial: they carry over as they are (tracks are immutable)
        out[clip.name] = Clip(clip.name, new, tracks, duration=clip.duration, loop=clip.loop,
                              morph_tracks=clip.morph_tracks)
    return new, out


def move_skeleton_points(skeleton, R):
    """The elk layout's conversion: joint heads and tails mapped by ``R``, joint frames kept
    axis-aligned (rest rotations stay identity), so clip keys apply unchanged in the new
    frame. Only for skeletons whose rest rotations are identity (heads-and-tails formats).
    """
    if not np.allclose(skeleton.rest_rotation[:, :3], 0.0, atol=1e-12):
        raise ValueError("expected a skeleton with identity rest rotations (joint heads and "
                         "tails) to move its points")
    return Skeleton(skeleton.names, skeleton.parents, skeleton.rest_translation @ R.T,
                    tails=skeleton.tails @ R.T, deform=skeleton.deform)


def joints_inside_score(vertices, points):
    """How well ``points`` (joint heads and tails) sit inside a mesh: the fraction inside the
    mesh's bounding box (grown by 2% of its diagonal), then minus the mean distance to the
    nearest vertex over the diagonal (to break ties). Higher is better."""
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    diag = float(np.linalg.norm(hi - lo)) or 1.0
    pad = 0.02 * diag
    inside = np.all((points >= lo - pad) & (points <= hi + pad), axis=1).mean()
    dist, _ = cKDTree(vertices).query(points)
    return float(inside), float(inside - dist.mean() / diag)


def resolve_folder_frames(path, skeleton, meta, vertices, manifest):
    """Decide the frames of a rig folder and convert its skeleton's points when needed.

    Parameters
    ----------
    path : Path
        The folder (for messages).
    skeleton : Skeleton
        As read from the skeleton file.
    meta : dict
        ``{"format": "elk" | "rigedit", "up": "y" | "z"}`` from the skeleton reader.
    vertices : (V, 3) float
        The mesh as read.
    manifest : dict
        ``rig.json`` as checked by :func:`rigedit.io.rig_folder.read_manifest` (``"up"`` and
        ``"skeleton_up"`` are ``"y"`` or ``"z"``): they win over a guess.

    Returns
    -------
    skeleton : Skeleton
        In the mesh's frame (elk layout: its points moved), or as read when ``clip_change``
        is not None.
    up : {"y", "z"}
        The rig's up axis (the mesh's).
    note : str or None
        What was decided (None when nothing needed deciding); also warned as
        :class:`FramesWarning` when the skeleton was converted.
    clip_change : (3, 3) float or None
        For rigedit's own skeleton format: the rotation to apply to the skeleton and its
        clips together, with :func:`change_axes`, once the clips are loaded.
    """
    skeleton_up = manifest.get("skeleton_up", meta["up"])
    if "skeleton_up" in manifest:
        up = manifest.get("up", skeleton_up)
        how = "stated in rig.json"
    elif meta.get("format") == "elk" and len(vertices):
        heads = skeleton.bind_matrices[:, :3, 3]
        tails = skeleton.tails[np.all(np.isfinite(skeleton.tails), axis=1)]
        points = np.vstack([heads, tails])
        as_is = joints_inside_score(vertices, points)
        moved = joints_inside_score(vertices, points @ Z_UP_TO_Y_UP.T)
        if moved[1] > as_is[1] and meta["up"] == "z" and manifest.get("up", "y") == "y":
            skeleton_up, up = "z", "y"
        else:
            up = manifest.get("up", meta["up"])
            skeleton_up = up
        how = (f"guessed: {moved[0]:.0%} of the joints lie inside the mesh's box with the "
               f"skeleton converted, {as_is[0]:.0%} as written")
    else:
        return skeleton, manifest.get("up", meta["up"]), None, None
    if skeleton_up == up:
        return skeleton, up, f"skeleton and mesh both {up.upper()} up ({how})", None
    R = axis_change(skeleton_up, up)
    if meta.get("format") != "elk":
        note = (f"skeleton {skeleton_up.upper()} up, mesh {up.upper()} up ({how}): skeleton "
                f"and clips converted together (rotation keys conjugated)")
        warnings.warn(f"{path}: {note}", FramesWarning, stacklevel=3)
        return skeleton, up, note, R
    try:
        skeleton = move_skeleton_points(skeleton, R)
    except ValueError as exc:
        raise RigFileError(path, str(exc)) from None
    mapping = "(x, y, z) -> (x, z, -y)" if skeleton_up == "z" else "(x, y, z) -> (x, -z, y)"
    note = (f"skeleton {skeleton_up.upper()} up, mesh {up.upper()} up: skeleton points "
            f"converted by {mapping}, clips played unchanged in the converted frame as the "
            f"elk project's viewer does ({how}; set \"up\" and \"skeleton_up\" in rig.json "
            f"to override)")
    warnings.warn(f"{path}: {note}", FramesWarning, stacklevel=3)
    return skeleton, up, note, None
