"""The work of one task, run on a worker: read the inputs by path, write the outputs
atomically into OUTDIR, measure, and return the manifest entry (a plain dict).

:func:`run_task` never raises for a task's own failure (a file that cannot be read, a
skeleton without legs, a full disk): the entry says ``failed`` with the one-line error, so
one broken file among a thousand is one failed row and the rest go on. Each job function
(``_autorig``, ``_retarget``, ``_render``, ``_convert``, ``_compress``, ``_noop``) takes the
task and returns its quality figures and the reasons a person should look (``unsure``).
"""
from __future__ import annotations

import copy
import datetime
import functools
import math
import os
import socket
import time
import warnings
from pathlib import Path

from .inputs import content_hash, quick_stamp
from .manifest import rigedit_version

__all__ = ["run_task", "one_line"]

#: Thumbnails: an animated GIF of this many frames at this size.
THUMB_FRAMES, THUMB_SIZE = 8, (192, 192)


def one_line(exc):
    """An exception as one line: a ``RigFileError``'s own words (they name the file), else
    its type and message, whitespace collapsed, at most 300 characters (a longer one loses
    its middle)."""
    from ..errors import RigFileError

    text = " ".join(str(exc).split())
    if not isinstance(exc, (RigFileError, OSError)) or not text:
        text = f"{type(exc).__name__}: {text}" if text else type(exc).__name__
    # too long: the middle goes, not the end (a deep path would push the problem out)
    return text if len(text) <= 300 else f"{text[:140]} ... {text[-155:]}"


def _load(source):
    """``Rig`` of a path or bundled name (weights computed where the file has none)."""
    from ..io.load import read_rig
    from ..rig import Rig

    return Rig.from_data(read_rig(source))


@functools.lru_cache(maxsize=8)
def _cached_rig(source, digest):
    """A target or template read once per worker process; ``digest`` (its content hash)
    makes a changed file a new read."""
    return _load(source)


def _rig_option(source, task):
    """The target or template ``source`` of ``task``, cached by the content hash the task
    recorded for it (a worker of a running cluster outlives batches: a file edited with its
    size and time kept, as ``cp -p`` or a tar leaves it, was served from the cache)."""
    digest = (task.get("hashes") or {}).get(source)
    return _cached_rig(source, digest or tuple(quick_stamp(source) or ()))


def _pick_clip(rig, name, what):
    """The clip ``name`` of ``rig``, or its first by name when None (a batch does not stop to
    ask which of several)."""
    from ..errors import RigFileError

    names = sorted(rig.clips)
    pick = name if name is not None else next(iter(names), None)
    if pick not in rig.clips:
        wanted = f"the clip {name!r}" if name is not None else "a clip"
        raise RigFileError(what, f"expected {wanted}, got "
                                 f"{'clips ' + ', '.join(names) if names else 'none'}")
    return rig.clips[pick]


def _thumbnail(task, rig, clip):
    """An animated GIF of ``clip`` on ``rig`` (the rest pose when None) at ``task``'s
    thumbnail path; a failure is a warning, not the task's."""
    if not task["thumbnail"]:
        return
    from ..render.recorder import record_clip

    path = Path(task["outdir"]) / task["thumbnail"]
    duration = clip.duration if clip is not None and clip.duration > 0 else 1.0
    frames = THUMB_FRAMES if clip is not None else 1
    try:
        path.parent.mkdir(exist_ok=True)   # a thumbs/ that cannot be made: a warning too
        record_clip(rig, clip, path, fps=frames / duration, duration=duration, size=THUMB_SIZE)
    except Exception as exc:   # no OpenGL on this worker, say: the output itself is fine
        warnings.warn(f"thumbnail not made: {one_line(exc)}")


def _out(task, i=0):
    return Path(task["outdir"]) / task["outputs"][i]


def _autorig(task):
    from ..io.save import save_rig
    from ..rigging.autorig.pipeline import autorig

    s = task["settings"]
    template = _rig_option(s["template"], task)
    rig = autorig(task["input"], template=template, up=s["up"], forward=s["forward"],
                  weights=s["method"], clips=s["clips"])
    report = rig.autorig_report
    save_rig(rig, _out(task))
    _thumbnail(task, rig, rig.clips.get("walk") or (_pick_clip(rig, None, task["input"])
                                                   if rig.clips else None))
    o = report.orientation
    quality = {"sure": bool(report.sure), "orientation": o.describe(),
               "orientation sure": bool(o.sure),
               "orientations tried": report.orientations[:2],
               "embedding cost": round(float(report.cost), 4),
               "joints placed": len(report.placed), "joints": len(rig.skeleton),
               "vertices": len(rig.vertices), "clips": sorted(rig.clips)}
    return quality, list(report.reasons)


def _retarget(task):
    import numpy as np

    from ..io.save import save_rig
    from ..rigging.retarget.measure import (direction_errors, foot_slip, lowest_foot,
                                            target_foot_points)
    from ..rigging.retarget.name_map import load_map, unmapped_parts
    from ..rigging.retarget.pipeline import retarget_result

    s = task["settings"]
    source = _load(task["input"])
    target = _rig_option(task["target"], task)
    clip = _pick_clip(source, s["clip"], task["input"])
    mapping = load_map(s["map"], source.skeleton, target.skeleton) if s["map"] else None
    res = retarget_result(source, clip, target, mapping, None, source_what=task["input"],
                          target_what=task["target"])
    tsk = target.skeleton
    unmapped = unmapped_parts(res.target_calibration, [tsk.index[t] for t in res.mapping.values()])
    errors = direction_errors(res)
    mean = [v for k, v in errors.items() if k != "worst" and np.isfinite(v)]
    slips = foot_slip(target_foot_points(res), res.contact)
    quality = {"mapped joints": len(res.mapping), "unmapped": unmapped,
               "bone direction error (deg)": round(float(np.mean(mean)), 2) if mean else None,
               "worst bone (deg)": round(float(errors["worst"]), 1),
               "feet lowest (cm)": round(100 * lowest_foot(res), 2),
               "feet slip max (cm)": round(100 * float(slips.max()), 2) if len(slips) else 0.0,
               "frames": len(res.times), "facing turn (deg)": round(float(res.facing_degrees), 1)}
    unsure = [f"unmapped: {part}" for part in unmapped]
    if res.facing_note:
        unsure.append(f"facing: {res.facing_note}")
    # the cached target is shared by the tasks of this worker process, several at once when
    # the worker runs threads (`dask worker` without --nthreads 1): each writes a shallow
    # copy with its own clips, never the shared one (two clips named "mixamo.com" swapped)
    result = copy.copy(target)
    result.clips = {**target.clips, res.clip.name: res.clip}
    clips = None if s["format"] == "folder" else [res.clip.name]
    save_rig(result, _out(task), clips=clips)
    _thumbnail(task, result, res.clip)
    return quality, unsure


def _render(task):
    from ..render.recorder import record_clip
    from .sheets import write_sheet

    s = task["settings"]
    rig = _load(task["input"])
    clip = _pick_clip(rig, s["clip"], task["input"])
    w, h = (int(v) for v in s["size"].split("x"))
    n = record_clip(rig, clip, _out(task, 0), fps=s["fps"], duration=s["duration"], size=(w, h),
                    view=s["view"])
    write_sheet(_out(task, 0), _out(task, 1))
    return {"frames": n, "clip": clip.name, "duration (s)": round(float(clip.duration), 2)}, []


def _convert(task):
    from ..io.save import save_rig

    s = task["settings"]
    rig = _load(task["input"])
    clips = [_pick_clip(rig, s["clip"], task["input"]).name] if s["to"] == "bvh" else None
    save_rig(rig, _out(task), clips=clips)
    _thumbnail(task, rig, rig.clips[clips[0]] if clips else
               (_pick_clip(rig, None, task["input"]) if rig.clips else None))
    return {"joints": len(rig.skeleton), "vertices": len(rig.vertices),
            "clips": sorted(rig.clips) if clips is None else clips}, []


def _noop(task):
    return {}, []


def _compress(task):
    from .compress_job import compress_task

    return compress_task(task, _load, _out(task), _thumbnail)


_JOBS = {"autorig": _autorig, "retarget": _retarget, "render": _render, "convert": _convert,
         "compress": _compress, "noop": _noop}


def _reads(task):
    """``{source: {"hash", "stamp"}}`` of what the task reads, taken before it reads them."""
    out = {}
    for src in task["reads"]:
        out[src] = {"hash": content_hash(src), "stamp": quick_stamp(src)}
    return out


def run_task(task):
    """Run one task; its manifest entry (``status`` ``ok`` or ``failed``), never an exception
    for the task's own failure. See :mod:`rigedit.batch.manifest` for the fields."""
    t0 = time.perf_counter()
    entry = {"task": task["id"], "job": task["job"], "input": task["input"],
             "target": task["target"], "inputs": {}, "settings": task["settings"],
             "rigedit": rigedit_version(), "outputs": task["outputs"], "thumbnail": None,
             "status": "failed", "error": None, "failure": None, "quality": {}, "unsure": [],
             "warnings": [], "worker": f"{socket.gethostname()}:{os.getpid()}"}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            entry["inputs"] = _reads(task)
            hashes = {src: read["hash"] for src, read in entry["inputs"].items()}
            entry["quality"], entry["unsure"] = _JOBS[task["job"]]({**task, "hashes": hashes})
            # what this task wrote, so that a resume can tell it from a file another batch
            # wrote later under the same name into the same OUTDIR
            entry["output_stamps"] = {o: quick_stamp(Path(task["outdir"]) / o)
                                      for o in task["outputs"]}
            entry["status"] = "ok"
        except Exception as exc:  # the task's failure: one row, the batch goes on
            entry["error"], entry["failure"] = one_line(exc), "error"
    seen = set()
    entry["warnings"] = [w for w in (" ".join(str(c.message).split())[:300] for c in caught)
                         if not (w in seen or seen.add(w))][:20]
    thumb = task["thumbnail"]
    if thumb and (Path(task["outdir"]) / thumb).is_file():
        entry["thumbnail"] = thumb
    entry["seconds"] = round(time.perf_counter() - t0, 3)
    entry["finished"] = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    entry["quality"] = _plain(entry["quality"])
    return entry


def _plain(value):
    """``value`` as strict JSON takes it: numpy scalars and arrays as numbers and lists, a
    NaN or an infinity as None (``manifest.json`` is for tools too: ``jq`` refuses ``NaN``,
    and ``json.dump`` raised on a ``float32`` in the client, ending the batch)."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if hasattr(value, "tolist") and not isinstance(value, (str, bytes)):   # numpy
        return _plain(value.tolist())
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if value is None or isinstance(value, (str, int, float)):
        return value
    return str(value)
