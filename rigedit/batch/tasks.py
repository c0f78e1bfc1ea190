"""A batch's plan: its options checked, and one task per input (and target), each a plain
dict a worker receives (paths and settings only, so it pickles small and travels anywhere).

A task: ``id``, ``job``, ``input``, ``target`` (a retarget's rig, else None), ``reads`` (every
file or bundled name it reads: input, target, template, map), ``settings`` (the job's
options, as the manifest records them), ``outputs`` (paths relative to OUTDIR), ``thumbnail``
(relative, or None), ``outdir``.
"""
from __future__ import annotations

import hashlib
import math
import os
import unicodedata
from collections import Counter
from pathlib import Path

from ..io.bundled import BUNDLED
from ..io.registry import RIG_FILE_SUFFIXES
from .inputs import BatchUsageError, name_bytes, rig_source
from .manifest import MANIFEST_DIR, task_id

__all__ = ["JOBS", "check_options", "plan", "THUMBS_DIR"]

THUMBS_DIR = "thumbs"

#: Each job's options and their defaults (a key the job does not take is bad input).
JOBS = {
    "autorig": {"template": "humanoid", "up": None, "forward": None, "method": "heat",
                "clips": True, "format": "glb"},
    "retarget": {"to": None, "map": None, "clip": None, "format": "glb"},
    "render": {"clip": None, "fps": 24.0, "size": "320x240", "view": "front",
               "duration": None, "video": "mp4"},
    "convert": {"to": None, "clip": None},
    "compress": {"max_error": None, "shell": 3.0},
    "noop": {},
}
#: Options every job takes.
COMMON = {"thumbnails": True}

_FORMATS = {"glb": ".glb", "folder": "", "bvh": ".bvh"}


def _choice(job, key, value, allowed):
    if value not in allowed:
        raise BatchUsageError(f"{job} --{key.replace('_', '-')}: expected one of "
                              f"{', '.join(allowed)}, got {value!r}")


def _size(text):
    try:
        w, h = (int(v) for v in str(text).lower().split("x"))
    except ValueError:
        w = h = 0
    if not (16 <= w <= 3840 and 16 <= h <= 2160) or w % 2 or h % 2:
        raise BatchUsageError(f"render --size: expected WIDTHxHEIGHT, even numbers from 16 to "
                              f"3840x2160, got {text!r}")
    return w, h


def _axes(up, forward):
    """``autorig --up/--forward``: axes (``y``, ``-x``), at right angles when both are given;
    a wrong one would fail every task alike, so it is refused before any."""
    from ..rigging.autorig.orient import check_axes

    try:
        check_axes(up, forward)
    except (ValueError, TypeError) as exc:
        raise BatchUsageError(f"autorig --up/--forward: {exc}") from None


def _target(text):
    """``retarget --to``: a bundled name, a rig folder or a rig file (a folder of rigs or a
    ``.txt`` would fail every task alike)."""
    source = rig_source(text)
    path = Path(source)
    if source in BUNDLED and not path.exists():
        return source
    if path.is_dir() and not (path / "skeleton.json").is_file():
        raise BatchUsageError(f"retarget --to {text}: expected a rig (a file or a folder "
                              f"holding a skeleton.json), got a folder without one")
    if path.is_file() and path.suffix.lower() not in RIG_FILE_SUFFIXES:
        raise BatchUsageError(f"retarget --to {text}: expected a rig file "
                              f"({', '.join(RIG_FILE_SUFFIXES)}), got a {path.suffix or 'file'}")
    return source


def _joint_map(path):
    """``retarget --map``: a JSON joint map (its names are checked against each task's
    skeletons there); one that is no map would fail every task alike."""
    from ..errors import RigFileError
    from ..rigging.retarget.map_files import load_map

    try:
        load_map(path)
    except RigFileError as exc:
        raise BatchUsageError(f"retarget --map: {exc}") from None


def _positive(job, key, value, high):
    if value is None:
        return None
    if not (isinstance(value, (int, float)) and math.isfinite(value) and 0 < value <= high):
        raise BatchUsageError(f"{job} --{key.replace('_', '-')}: expected a number in (0, "
                              f"{high:g}], got {value!r}")
    return float(value)


def check_options(job, options):
    """The job's settings: its defaults updated by ``options``, checked.

    Raises
    ------
    BatchUsageError
        An unknown job or option, or a value that makes no sense (naming it).
    """
    if job not in JOBS:
        raise BatchUsageError(f"expected a job ({', '.join(j for j in JOBS if j != 'noop')}), "
                              f"got {job!r}")
    known = {**JOBS[job], **COMMON}
    unknown = sorted(set(options) - set(known))
    if unknown:
        raise BatchUsageError(f"{job}: unknown option{'s' if len(unknown) > 1 else ''} "
                              f"{', '.join(unknown)} (it takes {', '.join(sorted(known))})")
    s = {**known, **{k: v for k, v in options.items() if v is not None}}
    if job == "autorig":
        s["template"] = rig_source(s["template"])
        _choice(job, "method", s["method"], ("heat", "idw"))
        _axes(s["up"], s["forward"])
        _choice(job, "format", s["format"], ("glb", "folder"))
    elif job == "retarget":
        targets = s["to"] if isinstance(s["to"], (list, tuple)) else [s["to"]] * bool(s["to"])
        if not targets:
            raise BatchUsageError("retarget: expected at least one target rig (--to RIG)")
        s["to"] = sorted({_target(t) for t in targets})
        if s["map"] is not None:
            s["map"] = rig_source(s["map"])
            _joint_map(s["map"])
        _choice(job, "format", s["format"], ("glb", "folder"))
    elif job == "render":
        if not s["clip"]:
            raise BatchUsageError("render: expected the clip to render (--clip NAME)")
        _size(s["size"])
        s["fps"] = _positive(job, "fps", s["fps"], 240)
        s["duration"] = _positive(job, "duration", s["duration"], 3600)
        _choice(job, "view", s["view"], ("front", "side", "back", "top"))
        _choice(job, "video", s["video"], ("mp4", "gif"))
    elif job == "convert":
        _choice(job, "to", s["to"], tuple(_FORMATS))
    elif job == "compress":
        s["max_error"] = _positive(job, "max_error", s["max_error"], 100)
        s["shell"] = _positive(job, "shell", s["shell"], 100)
        if s["max_error"] is None:
            raise BatchUsageError("compress: expected --max-error CM")
    return s


def _outputs(job, base, settings):
    """Output names (relative to OUTDIR) of one task whose outputs are called ``base``."""
    if job in ("autorig", "retarget"):
        return [base + _FORMATS[settings["format"]]]
    if job == "render":
        # a clip's name may hold a slash ("Take 001/run"): no sub-folder of OUTDIR
        clip = settings["clip"].replace("/", "_").replace(chr(0), "_")
        name = f"{base}_{_short(clip, MAX_CLIP_BYTES)}"
        return [f"{name}.{settings['video']}", f"{name}_sheet.png"]
    if job == "convert":
        return [base + _FORMATS[settings["to"]]]
    if job == "compress":
        return [base + ".glb"]
    return []


def _pairs(job, sources, settings):
    if job == "retarget":
        return [(s, t) for s in sources for t in settings["to"]]
    return [(s, None) for s in sources]


#: Names in OUTDIR that are the batch's own: an output called so would overwrite them (a
#: rig folder ``manifest/`` mixed with the entries) or be mistaken for them.
RESERVED = {MANIFEST_DIR, THUMBS_DIR, "manifest.json", "report.html"}
#: Longest output base in UTF-8 bytes: a file name has 255, and the writers' temporary
#: names (``.NAME.pid123-abcdefgh.tmp``) add about 30.
MAX_BASE_BYTES = 160
#: Longest clip name in a render's output names (``BASE_CLIP_sheet.png``), in bytes.
MAX_CLIP_BYTES = 40


def _short(text, limit=MAX_BASE_BYTES):
    """``text`` cut to ``limit`` bytes at a character's boundary."""
    return name_bytes(text)[:limit].decode(errors="ignore")


def _tagged(base, digest):
    """``BASE-DIGEST``, ``base`` cut so that the whole stays within :data:`MAX_BASE_BYTES`."""
    return f"{_short(base, MAX_BASE_BYTES - 1 - len(digest))}-{digest}"


def _unique_bases(job, pairs, settings):
    """An output base name per pair: the input's stem (and the target's). A name that two
    pairs share (``a/walk.bvh`` and ``b/walk.bvh``; two targets ``x/hero.glb`` and
    ``y/hero.glb``), whose output would be one of the batch's own files (:data:`RESERVED`)
    or that is too long for a file name gets a short hash of the input's path (and the
    target's), so no task overwrites another's output or the manifest. Names are compared
    as a file system that ignores case and Unicode normalization would (``Walk.bvh`` and
    ``walk.bvh`` are one file on macOS, Windows and many NAS shares)."""
    bases = [Path(str(s)).stem + (f"__{Path(str(t)).stem}" if t else "") for s, t in pairs]
    seen = Counter(map(_fold, bases))

    def clash(base):
        return (seen[_fold(base)] > 1 or len(name_bytes(base)) > MAX_BASE_BYTES
                or any(_fold(Path(o).parts[0]) in RESERVED
                       for o in _outputs(job, base, settings)))

    def tag(source, target, digits):
        key = str(source) + (f"\0{target}" if target else "")
        return hashlib.sha1(name_bytes(key)).hexdigest()[:digits]

    out = [_tagged(b, tag(s, t, 6)) if clash(b) else b for b, (s, t) in zip(bases, pairs)]
    # 6 hex digits are 24 bits: 20,000 files named take.bvh gave 10 pairs one output name
    # (or a name may be another input's literally); those get the whole hash
    again = Counter(map(_fold, out))
    return [_tagged(b, tag(s, t, 40)) if again[_fold(o)] > 1 else o
            for o, b, (s, t) in zip(out, bases, pairs)]


def _fold(name):
    """``name`` as a case-insensitive, normalizing file system sees it."""
    return unicodedata.normalize("NFC", name).casefold()


def plan(job, sources, outdir, settings):
    """One task dict per input (a retarget: per input and target), in input order.

    Parameters
    ----------
    job : str
    sources : list of Path or str
        :func:`rigedit.batch.inputs.expand_inputs`'s list.
    outdir : Path
    settings : dict
        :func:`check_options`'s result.

    Raises
    ------
    BatchUsageError
        A task would write over a file some task reads (``rigedit batch compress *.glb -o .``
        replaced the originals with their lossy copies).
    """
    pairs = _pairs(job, sources, settings)
    ids = [task_id(job, s, t) for s, t in pairs]
    twice = Counter(ids)
    ids = [task_id(job, s, t, 40) if twice[i] > 1 else i for i, (s, t) in zip(ids, pairs)]
    tasks = []
    for (source, target), base, tid in zip(pairs, _unique_bases(job, pairs, settings), ids):
        reads = [str(source)] + ([target] if target else [])
        reads += [settings[k] for k in ("template", "map") if settings.get(k)]
        task_settings = {k: v for k, v in settings.items() if k != "to" or job != "retarget"}
        outputs = _outputs(job, base, settings)
        thumb = outputs[1] if job == "render" else (
            f"{THUMBS_DIR}/{tid}.gif" if settings["thumbnails"] and job != "noop" else None)
        tasks.append({"id": tid, "job": job, "input": str(source), "target": target,
                      "reads": reads, "settings": task_settings, "outputs": outputs,
                      "thumbnail": thumb, "outdir": str(outdir)})
    _check_no_overwrite(tasks, outdir)
    return tasks


def _check_no_overwrite(tasks, outdir):
    """``BatchUsageError`` when an output (or a preview) of a task is a file a task reads."""
    real = Path(os.path.realpath(outdir))
    written = {real / rel for t in tasks
               for rel in t["outputs"] + ([t["thumbnail"]] if t["thumbnail"] else [])}
    for t in tasks:
        for source in t["reads"]:
            path = Path(os.path.realpath(source)) if os.path.isabs(source) else None
            if path in written:
                raise BatchUsageError(f"{source}: a task would write its output over this "
                                      f"input (it is in OUTDIR); give another -o")
