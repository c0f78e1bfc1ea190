"""``compress_clips``: every clip of a skeleton compressed with a guaranteed error.

Per clip: sample it at every frame (:mod:`.frames`), give each joint its share of the bound
(:mod:`.budget`), drop or store once what does not move (:mod:`.constant`), quantise and
reduce the rest (:mod:`.encode`), write the blob (:mod:`.layout`), decode it back
(:mod:`.codec`) and measure every frame on virtual vertices in model space (:mod:`.error`).
Where a joint is over the bound, the joints on its path to the root get half their share and
are encoded again, until every frame of the clip holds.
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import numpy as np

from ..animation.clip import Clip
from ..animation.track import Track
from ..model.pose import Pose
from ..progress import adapt
from .budget import Budget, with_ancestors
from .compressed_clip import CompressedClip, KeyedClip
from .encode import encode_tracks, gltf_tracks
from .constant import spread
from .error import ErrorMeter
from .kernels import load
from .frames import COLUMNS, frame_times
from .layout import ClipLayout, grid_times, key_code, write_clip
from .quantise import PER_KEY, SEGMENT, SEGMENT_HEADER_BITS
from .cubic import align_to
from .reduce_cubic import half_frames
from .report import RAW_BYTES_PER_JOINT_FRAME, ClipRow, CompressionReport
from .virtual import DEFAULT_SHELL, check_shell, shell_distances

__all__ = ["TARGETS", "SECTION_BYTES", "CompressionResult", "compress_clips",
           "check_max_error", "HalfFrameWarning"]

TARGETS = ("rigedit", "gltf")
#: Bytes a clip's section header takes in a .rgc file (tag, length, CRC32), counted in the
#: compressed size.
SECTION_BYTES = 12
#: Encodes per clip before giving up (each halves the offending joints' shares: 2^-16 of
#: the bound is past float32's precision for anything but a microscopic bound).
MAX_ATTEMPTS = 16
#: Encodes that try larger shares where the check found room (:meth:`Budget.relax`).
RELAX_ROUNDS = 3
_GLTF_MODE = {"translation": "linear", "rotation": "nlerp", "scale": "linear"}


@dataclass
class CompressionResult:
    """``clips``: name -> :class:`CompressedClip` (``target="rigedit"``) or
    :class:`KeyedClip` (``"gltf"``); ``report``: :class:`CompressionReport`."""

    clips: dict
    report: CompressionReport


def check_max_error(max_error):
    """``max_error`` as a positive finite float (metres); ``ValueError`` otherwise."""
    try:
        value = float(max_error)
    except (TypeError, ValueError):
        raise ValueError(f"expected max_error as a positive number of metres, got "
                         f"{max_error!r}") from None
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"expected max_error as a positive finite number of metres, got "
                         f"{max_error!r}")
    return value


def _grid(times, target="rigedit"):
    """``(uniform, decoded times, wide)`` of a clip's frames (F,): a uniform grid (start,
    period) when the frames are evenly spaced to 1e-7 s; else the float32 times, or, where
    float32 would merge two frames (keys 2e-6 s apart at 100 s) or move one by more than 1%
    of its gap to a neighbour (keys 1e-7 s apart), float64 ones (``wide``) in
    rigedit's format and, in glTF's (float32 only), float32 times kept strictly increasing
    (:func:`increasing_float32`), the check then measuring what that costs."""
    f = len(times)
    period = float((times[-1] - times[0]) / (f - 1)) if f > 1 else 0.0
    uniform = (float(times[0]), period)
    grid = grid_times(f, uniform)
    if np.max(np.abs(grid - times)) <= 1e-7:
        return uniform, grid, False
    grid = grid_times(f, None, times)
    gaps = np.diff(times)
    nearest = np.minimum(np.r_[np.inf, gaps], np.r_[gaps, np.inf])
    if np.all(np.diff(grid) > 0) and np.all(np.abs(grid - times) <= 0.01 * nearest):
        return None, grid, False
    if target == "gltf":
        return None, increasing_float32(times), False
    return None, grid_times(f, None, times, wide=True), True


def increasing_float32(times):
    """Times (F,) float64, increasing, rounded to float32 and then kept strictly increasing
    (a frame float32 cannot tell from the one before it goes one float32 step later), as
    float64."""
    t32 = np.asarray(times, dtype=np.float32)
    merged = np.flatnonzero(np.diff(t32) <= 0)
    for i in range(merged[0] + 1 if len(merged) else len(t32), len(t32)):
        if t32[i] <= t32[i - 1]:   # after a nudge the next frame may be merged in turn
            t32[i] = np.nextafter(t32[i - 1], np.float32(np.inf))
    return t32.astype(np.float64)


def _kinds(layout, size):
    """Compressed bytes per kind of one clip blob (section header included in ``header``)."""
    kinds = dict.fromkeys(("rotation", "translation", "scale", "times", "header"), 0.0)
    kinds["times"] += 0 if layout.uniform else (8 if layout.wide else 4) * len(layout.times)
    for tr in layout.constant:
        kinds[tr.channel] += 4 * len(tr.value)
    frames = len(layout.times)
    for tr in layout.animated:
        k = len(tr.keys)
        if tr.segments is not None:   # read back: (used segments, a, b, bits)
            used, _, _, bits = tr.segments
            which = np.searchsorted(used, tr.keys // SEGMENT)
            kinds[tr.channel] += (bits[which].sum() + len(used) * SEGMENT_HEADER_BITS) / 8
        else:
            stride = int(np.sum(tr.code.bits)) + (2 if tr.mode == PER_KEY else 0)
            kinds[tr.channel] += k * stride / 8
        kinds["times"] += key_code(tr.keys, frames)[1] / 8
    kinds = {k: int(round(v)) for k, v in kinds.items()}
    kinds["header"] = size - sum(v for k, v in kinds.items() if k != "header")
    return kinds


def _compress_one(skeleton, clip, max_error, distances, target, shell, mesh):
    """One clip: ``(compressed clip, (F, J) errors, ClipRow)``."""
    times = frame_times(clip)
    meter = ErrorMeter(skeleton, clip, times, shell, mesh)
    budget = Budget(skeleton, max_error, distances)
    uniform, grid, wide = _grid(times, target)
    ref = meter.local
    halves = HalfFrames(meter, clip, shell, mesh) if len(times) > 1 else None
    rest = Pose(skeleton).as_array()
    sources = [(skeleton.index[name], channel) for name, channel in clip.tracks]
    cache = {}
    spreads = {(j, c): spread(ref[:, j, COLUMNS[c]], rest[j, COLUMNS[c]], c == "rotation")
               for j, c in sources}
    best, relax, frames_only = None, RELAX_ROUNDS, None
    linear = np.zeros(len(skeleton), dtype=bool)     # joints kept to linear keys
    for attempt in range(1, MAX_ATTEMPTS + 1):
        tols = {(j, c): (budget.tolerance(j, c), bool(linear[j])) for j, c in sources}
        todo = [(j, c) for j, c in sources if cache.get((j, c), (None,))[0] != tols[(j, c)]]
        batch = [(j, c, ref[:, j, COLUMNS[c]], rest[j, COLUMNS[c]], tols[(j, c)][0],
                  spreads[(j, c)]) for j, c in todo]
        mids = None if halves is None else [halves.meter.local[:, j, COLUMNS[c]]
                                            for j, c in todo]
        if target == "gltf":
            done = gltf_tracks(batch, grid, mids)
        else:
            done = encode_tracks(batch, grid, mids, [not linear[j] for j, c in todo])
        cache.update({key: (tols[key], enc) for key, enc in zip(todo, done)})
        stored = {key: cache[key][1] for key in sources if cache[key][1] is not None}
        compressed = (_rigedit_clip if target == "rigedit" else _gltf_clip)(
            skeleton, clip, stored, uniform, grid, wide)
        err = meter.error(compressed)
        worst = err.max(axis=0)
        if halves is not None and worst.max() <= max_error:
            between = halves.excess(compressed)
            if frames_only is None or between.max() < frames_only[3]:
                frames_only = (compressed, err, attempt, between.max())
            if _cubic_strays(skeleton, compressed, between > max_error, linear):
                continue
            worst = np.maximum(worst, between)
        if worst.max() <= max_error:
            if best is None or compressed.nbytes < best[0].nbytes:
                best = (compressed, err, attempt)
            if not relax:
                break
            relax -= 1
            budget.relax(worst)
        else:
            budget.tighten(np.flatnonzero(worst > max_error), 0.5 if best is None else 0.8)
    if best is None and frames_only is not None:
        # every frame holds, a half-frame does not (what keys at frames cannot mend, beyond
        # the source's own bend between frames): kept, and said
        warnings.warn(f"clip {clip.name!r}: halfway between frames the error reaches "
                      f"{frames_only[3] * 100:.3g} cm over the source's own frames joined "
                      f"straight, past the bound {max_error * 100:g} cm; every frame holds it",
                      HalfFrameWarning)
        best = frames_only[:3]
    if best is None:
        raise ValueError(f"clip {clip.name!r}: cannot hold max_error {max_error:g} m "
                         f"({max_error * 100:g} cm; still {err.max() * 100:.3g} cm after "
                         f"{MAX_ATTEMPTS} encodes)")
    compressed, err, attempt = best
    return compressed, err, _row(clip, compressed, err, len(times), attempt, len(sources),
                                 skeleton)


class HalfFrameWarning(UserWarning):
    """A clip holds its bound at every frame but not halfway between two of them."""


class HalfFrames:
    """The check halfway between frames (a line over several frames of a fast swing strays
    most there, and a cubic bends there).

    What is held is the error the compressor adds: a joint's error at each half-frame less
    the error there of the source's own frames joined by LERP / NLERP (``floor``, (H, J)),
    which no key at a frame mends (a source that curves between its frames: a spline clip
    checked at 30 Hz). For a source keyed at its frames with LINEAR or SLERP samplers the
    floor is 0 (NLERP's midpoint is SLERP's).
    """

    def __init__(self, frames, clip, shell, mesh):
        """``frames``: the :class:`ErrorMeter` of the clip's frames (its source poses are
        what is joined)."""
        self.meter = ErrorMeter(frames.skeleton, clip, half_frames(frames.times), shell, mesh)
        local = frames.local
        joined = 0.5 * (local[:-1] + local[1:])            # u = 1/2: LERP, and NLERP below
        q0 = local[:-1, :, 3:7]
        q = q0 + align_to(local[1:, :, 3:7], q0)
        joined[..., 3:7] = q / np.linalg.norm(q, axis=-1, keepdims=True)
        self.floor = self.meter.error_of_local(joined)

    def excess(self, compressed):
        """(J,) each joint's largest error over its floor at the half-frames."""
        return np.maximum(self.meter.error(compressed) - self.floor, 0.0).max(axis=0)


def _cubic_strays(skeleton, compressed, over, linear):
    """Whether the clip's Catmull-Rom keys may be what takes the joints ``over`` (J,) bool past
    the bound halfway between frames; if so, the joints with cubic keys on the path from each
    of them to the root are marked in ``linear`` (J,) bool, to be encoded again with linear
    keys (the reducer holds each cubic track to its share at the half-frames, but shares add
    up in model space)."""
    if not over.any() or isinstance(compressed, KeyedClip):
        return False
    cubic = np.zeros(len(skeleton), dtype=bool)
    for tr in compressed.layout.animated:
        cubic[tr.joint] |= tr.cubic
    mend = with_ancestors(skeleton, np.flatnonzero(over)) & cubic & ~linear
    linear |= mend
    return bool(mend.any())


def _row(clip, compressed, err, frames, attempts, sources, skeleton):
    size = compressed.nbytes + SECTION_BYTES
    if isinstance(compressed, CompressedClip):
        layout = compressed.layout
        animated, constant = len(layout.animated), len(layout.constant)
        keys = sum(len(tr.keys) for tr in layout.animated)
        kinds = _kinds(layout, size)
    else:
        tracks = compressed.clip.tracks.values()
        constant = sum(len(tr) == 1 for tr in tracks)
        animated = len(tracks) - constant
        keys = sum(len(tr) for tr in tracks if len(tr) > 1)
        kinds = compressed.kinds
    return ClipRow(clip.name, frames, len(skeleton), float(err.max()),
                   float(np.percentile(err, 99)), frames * len(skeleton) *
                   RAW_BYTES_PER_JOINT_FRAME, size, kinds,
                   {"animated": animated, "constant": constant,
                    "omitted": sources - animated - constant}, keys, attempts)


def _rigedit_clip(skeleton, clip, stored, uniform, grid, wide):
    constant = [tr for tr in stored.values() if tr.keys is None]
    animated = [tr for tr in stored.values() if tr.keys is not None]
    layout = ClipLayout(clip.name, float(clip.duration), clip.loop, grid, uniform,
                        constant, animated, wide)
    packed = CompressedClip(skeleton, write_clip(layout))
    if load("reduce_kernels") is not None:   # numba is in already: check with the kernels
        packed.use_kernels()
    return packed


def _gltf_clip(skeleton, clip, stored, uniform, grid, wide=False):
    tracks, kinds = {}, dict.fromkeys(("rotation", "translation", "scale", "times",
                                       "header"), 0)
    seen = set()     # a list of key times is one accessor, shared (io/gltf_write_compact)
    for (j, channel), (times, values) in stored.items():
        tracks[(skeleton.names[j], channel)] = Track(channel, times.astype(np.float32),
                                                     values, _GLTF_MODE[channel])
        kinds[channel] += len(times) * (8 if channel == "rotation" else 12)
        key = times.astype(np.float32).tobytes()
        kinds["times"] += 0 if key in seen else 4 * len(times)
        seen.add(key)
    keyed = KeyedClip(Clip(clip.name, skeleton, tracks, clip.duration, clip.loop),
                      sum(kinds.values()))
    keyed.kinds = kinds
    return keyed


def compress_clips(skeleton, clips, max_error=1e-4, shell=DEFAULT_SHELL, mesh=None,
                   target="rigedit", progress=None):
    """Compress clips so that no virtual vertex of any frame strays more than ``max_error``.

    Parameters
    ----------
    skeleton : Skeleton
    clips : dict[str, Clip]
    max_error : float
        Metres (model space), > 0.
    shell : float
        Metres from each joint to its virtual vertices (ACL's 3 cm by default).
    mesh : (vertices (V, 3), indices (V, K), weights (V, K)), optional
        The rig's skin at bind: each joint's shell from its farthest vertex.
    target : {"rigedit", "gltf"}
        ``rigedit``: rigedit's own format, everything quantised (:class:`CompressedClip`);
        ``gltf``: what glTF's core holds (float32 times, translations and scales; rotations
        on the normalised int16 grid), reduced keys (:class:`KeyedClip`).
    progress : callable(fraction, stage), optional

    Returns
    -------
    CompressionResult
        ``report.max_error`` never exceeds ``max_error``: every frame is checked after
        decoding.

    Raises
    ------
    ValueError
        ``max_error`` or ``shell`` not a positive finite number, an unknown target, or a
        bound no encoding reaches.
    """
    max_error = check_max_error(max_error)
    shell = check_shell(shell)
    if target not in TARGETS:
        raise ValueError(f"expected target in {TARGETS}, got {target!r}")
    progress = adapt(progress, "compress")
    start = time.perf_counter()
    distances = shell_distances(skeleton, shell, mesh)
    report = CompressionReport(max_error, shell, target)
    out, errors = {}, []
    clips = dict(clips)
    for i, (name, clip) in enumerate(clips.items()):
        progress(i / max(len(clips), 1), f"compress {name}")
        out[name], err, row = _compress_one(skeleton, clip, max_error, distances, target,
                                            shell, mesh)
        errors.append(err)
        report.clips.append(row)
    progress(1.0, "compress")
    return CompressionResult(out, report.finish(errors, time.perf_counter() - start))
