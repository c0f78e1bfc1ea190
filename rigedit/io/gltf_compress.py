"""Clips compressed into a compact glTF with the bound checked on what a glTF reader gets.

:func:`rigedit.compression.compress_clips` with ``target="gltf"`` reduces keys measuring its
own interpolation between them (NLERP for rotations). A glTF reader plays a LINEAR rotation
as SLERP (glTF 2.0, "Interpolation") on the int16 values the file stores. The two agree to
within the int16 step where keys are close, not where a reduced track's keys are far apart
(between keys 20 degrees of rotation apart NLERP and SLERP part by up to 1.7e-4 rad). So here:

1. the compressor's keys become SLERP tracks, and each clip *as the file will be read*
   (:func:`as_read`: float32 times rounded as the writer rounds them, rotations decoded from
   their normalised SHORT and renormalised, vectors as float32) is measured against the
   source on the compressor's own frames and virtual vertices
   (:class:`rigedit.compression.error.ErrorMeter`);
2. a clip over the bound is compressed again with its bound scaled by what it missed by
   (``bound * 0.9 * max_error / measured``, at most halved per try), at most
   :data:`ATTEMPTS` times;
3. a clip that no compression holds on the int16 grid (a long chain where the grid's step at
   the root alone moves the hands past the bound) is written with its own keys and float32
   rotations, said in one warning;
4. the file is written (:mod:`rigedit.io.gltf_write_compact`) and the report's sizes are the
   bytes of its animation data as stored.

The report is a :class:`rigedit.compression.CompressionReport` whose errors are those of the
glTF as read: its ``max_error`` never exceeds the bound.
"""
from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np

from ..animation.clip import Clip, Track
from ..compression import CompressionReport, compress_clips
from ..compression.error import ErrorMeter
from ..compression.frames import frame_times
from ..compression.report import RAW_BYTES_PER_JOINT_FRAME, ClipRow
from ..errors import RigFileError
from .gltf_write import _float32_times, save_gltf
from .gltf_write_compact import (CompactAnimations, decoded_rows, is_rest, rest_value,
                                 same_channels)

__all__ = ["ATTEMPTS", "as_read", "slerp_keys", "fit_clips", "save_gltf_compressed_rig"]

#: Compressions of one clip before its bound is given up as unreachable.
ATTEMPTS = 8
_SLERP = {"nlerp": "slerp", "linear": "slerp"}
_MODES = {"STEP": "step", "LINEAR": "linear", "CUBICSPLINE": "cubic_spline"}


def slerp_keys(clip):
    """The same keys with rotations interpolated as glTF's LINEAR does (SLERP)."""
    tracks = {}
    for key, tr in clip.tracks.items():
        if tr.channel == "rotation" and tr.interpolation in _SLERP and len(tr.times) > 1:
            tr = Track("rotation", tr.times, tr.values, "slerp")
        tracks[key] = tr
    return Clip(clip.name, clip.skeleton, tracks, clip.duration, clip.loop)


def as_read(clip, float_rotations=False):
    """``clip`` as rigedit's (or any spec-following) glTF reader gets it back from the compact
    writer: float32 key times as the writer rounds them, and the output rows it stores
    decoded (:func:`~rigedit.io.gltf_write_compact.decoded_rows`; all float32 with
    ``float_rotations``)."""
    tracks = {}
    for key, tr in clip.tracks.items():
        kind, rows = decoded_rows(tr, float_rotations or
                                  is_rest(tr, rest_value(clip.skeleton, *key)))
        times = _float32_times(tr.times).astype(np.float64)
        tangents, mode = None, _MODES[kind]
        if kind == "CUBICSPLINE":
            tri = rows.reshape(len(times), 3, -1)
            rows, tangents = tri[:, 1], tri[:, [0, 2]]
        elif mode == "linear" and tr.channel == "rotation":
            mode = "slerp"
        tracks[key] = Track(tr.channel, times, rows, mode, tangents)
    return Clip(clip.name, clip.skeleton, tracks, clip.duration, clip.loop)


def _fit_one(skeleton, name, clip, max_error, shell, mesh):
    """``(keys to write, (F, J) errors as read, attempts, float rotations)`` of one clip."""
    meter = ErrorMeter(skeleton, clip, frame_times(clip), shell, mesh)
    bound = max_error
    for attempt in range(1, ATTEMPTS + 1):
        try:
            result = compress_clips(skeleton, {name: clip}, max_error=bound, shell=shell,
                                    mesh=mesh, target="gltf")
        except ValueError:   # the int16 grid alone errs more than the bound
            return _float_fallback(meter, name, clip, max_error, attempt)
        keys = slerp_keys(result.clips[name].to_clip())
        err = meter.error(as_read(keys))
        worst = float(err.max())
        if worst <= max_error:
            return keys, err, attempt, False
        # what it missed by, at most halved per try (the miss is not linear in the bound)
        bound *= max(0.5, min(0.9 * max_error / worst, 0.9))
    return _float_fallback(meter, name, clip, max_error, ATTEMPTS)


def _float_fallback(meter, name, clip, max_error, attempts):
    """The clip's own keys with float32 rotations, when no compression holds the bound on the
    int16 grid (a long chain: the grid's step at the root moves the hands): said in one
    warning; ``ValueError`` if even that errs more than the bound."""
    keys = slerp_keys(clip)
    err = meter.error(as_read(keys, float_rotations=True))
    if err.max() > max_error:
        raise ValueError(f"clip {name!r}: cannot hold max_error {max_error:g} m "
                         f"({max_error * 100:g} cm) in glTF (its own keys with float32 "
                         f"rotations err {err.max() * 100:.3g} cm)")
    warnings.warn(f"clip {name!r}: glTF's int16 rotations alone err more than "
                  f"{max_error * 100:g} cm on this skeleton: its keys are written uncompressed "
                  "with float32 rotations (rigedit's own format compresses it)")
    return keys, err, attempts, True


def fit_clips(skeleton, clips, max_error=1e-4, shell=0.03, mesh=None):
    """Compress ``clips`` for glTF so that every frame *as read from the file* holds.

    Parameters
    ----------
    skeleton : Skeleton
    clips : dict[str, Clip]
    max_error, shell : float
        Metres (see :func:`rigedit.compression.compress_clips`).
    mesh : (vertices (V, 3), indices (V, K), weights (V, K)), optional

    Returns
    -------
    keys : dict[str, Clip]
        Reduced keys to write (SLERP rotations).
    report : CompressionReport
        Errors as read; sizes still 0 (:func:`save_gltf_compressed_rig` fills them).
    float_clips : set[str]
        Clips whose int16 rotations alone err more than the bound: their own keys, to be
        written with float32 rotations (one warning each).
    """
    start = time.perf_counter()
    report = CompressionReport(max_error, shell, "gltf")
    keys, attempts, floats = {}, {}, set()
    for name, clip in clips.items():
        keys[name], _, attempts[name], flt = _fit_one(skeleton, name, clip, max_error, shell,
                                                      mesh)
        if flt:
            floats.add(name)
    keys = same_channels(keys)   # what the writer writes: measured again as read
    errors = []
    for name, clip in clips.items():
        err = ErrorMeter(skeleton, clip, frame_times(clip), shell, mesh).error(
            as_read(keys[name], float_rotations=name in floats))
        if err.max() > max_error:
            raise ValueError(f"clip {name!r}: {err.max():.3g} m over max_error {max_error:g} m "
                             "once every clip keys the same channels")
        errors.append(err)
        tracks = keys[name].tracks.values()
        constant = sum(len(tr) == 1 for tr in tracks)
        report.clips.append(ClipRow(
            name, err.shape[0], len(skeleton), float(err.max()),
            float(np.percentile(err, 99)), err.shape[0] * len(skeleton) *
            RAW_BYTES_PER_JOINT_FRAME, 0, {}, {"animated": len(tracks) - constant,
                                              "constant": constant,
                                              "omitted": max(len(clip.tracks) - len(tracks),
                                                             0)},
            sum(len(tr) for tr in tracks if len(tr) > 1), attempts[name]))
    return keys, report.finish(errors, time.perf_counter() - start), floats


def save_gltf_compressed_rig(rig, path, clips=None, max_error=1e-4, shell=0.03, mesh=None,
                             meshopt=False):
    """Compress ``rig``'s clips (names ``clips``, all when None) and write ``path`` (.glb or
    .gltf) with the rig's mesh and skin, atomically.

    Returns
    -------
    CompressionReport
        Errors of the file as read, sizes of its animation data as stored.

    Raises
    ------
    RigFileError
        Naming the file: an unknown clip, a bound no compression reaches, data glTF cannot
        hold, or ``meshopt`` without the meshopt package.
    """
    path = Path(path)
    names = list(rig.clips) if clips is None else list(clips)
    try:
        unknown = next((n for n in names if n not in rig.clips), None)
        if unknown is not None:
            raise ValueError(f"unknown clip {unknown!r} (the rig has "
                             f"{', '.join(rig.clips) or 'none'})")
        keys, report, floats = fit_clips(rig.skeleton, {n: rig.clips[n] for n in names},
                                         max_error, shell, mesh)
        compact = CompactAnimations(keys, meshopt=meshopt, float_clips=floats)
    except ValueError as exc:
        raise RigFileError(path, str(exc)) from None
    save_gltf(rig, path, compact=compact)
    stored = compact.bytes_by_clip()
    for row in report.clips:
        kinds = stored[row.name]
        row.bytes_by_kind = dict(kinds, header=0)
        row.compressed_bytes = sum(kinds.values())
    return report
