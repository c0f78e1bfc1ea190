"""The batch manifest: one JSON entry per task in ``OUTDIR/manifest/<task>.json``.

Each entry is written whole by the client, to a temporary file renamed over the old one
(:func:`rigedit.io.atomic.write_json`), so an interrupted batch leaves every entry either as
it was or complete: never half written, never listed twice (a task's entry is one file named
by the task). ``OUTDIR/manifest.json`` gathers them all at the end of each run, for people
and tools; the per-task files are what ``--resume`` reads.

An entry's fields: ``task`` (its id), ``job``, ``input``, ``target`` (a retarget's target
rig, None otherwise), ``inputs`` (every file read: ``{path: {"hash": "sha256:...",
"stamp": [size, mtime_ns]}}``), ``settings`` (the job's options), ``rigedit`` (version),
``outputs`` (paths relative to OUTDIR), ``output_stamps`` (``{output: [size, mtime_ns]}`` as
the task wrote them), ``thumbnail``, ``status`` (``ok`` or ``failed``),
``error`` (one line), ``failure`` (``error``: the task raised; ``lost``: its worker died
twice), ``seconds``, ``finished`` (UTC, ISO 8601), ``worker``, ``quality`` (the job's
figures), ``unsure`` (reasons a person should look), ``warnings``.
"""
from __future__ import annotations

import hashlib
import json
import re
from importlib import metadata
from pathlib import Path

from ..io.atomic import write_json
from .inputs import content_hash, name_bytes, quick_stamp

__all__ = ["Manifest", "task_id", "rigedit_version", "MANIFEST_DIR"]

MANIFEST_DIR = "manifest"
#: An entry file larger than this is not an entry of ours (never read whole).
MAX_ENTRY_BYTES = 4 << 20


def rigedit_version():
    """The installed rigedit's version (recorded in every entry; a new version re-runs)."""
    try:
        return metadata.version("rigedit")
    except metadata.PackageNotFoundError:
        return "unknown"


def _slug(text, limit=40):
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text)[:limit].strip("._") or "task"


def task_id(job, source, target=None, digits=10):
    """A task's stable id: readable (the input's and target's names) and unique (a hash of
    the job, the input's full path and the target, ``digits`` hex digits of it: a plan
    gives the rare pair of tasks whose 10 digits agree more)."""
    key = "\0".join([job, str(source), str(target or "")])
    digest = hashlib.sha1(name_bytes(key)).hexdigest()[:digits]   # a name may be no UTF-8
    name = Path(str(source)).stem + (f"__{Path(str(target)).stem}" if target else "")
    return f"{job}-{_slug(name)}-{digest}"


class Manifest:
    """The entries of one OUTDIR.

    Parameters
    ----------
    outdir : Path
        The batch's output folder (it exists).
    """

    def __init__(self, outdir):
        self.outdir = Path(outdir)
        self.folder = self.outdir / MANIFEST_DIR

    def path(self, tid):
        return self.folder / f"{tid}.json"

    def read(self, tid):
        """The entry of task ``tid``, or None when there is none or it is not one of ours."""
        return _read_entry(self.path(tid))

    def write(self, entry):
        """Write ``entry`` atomically (replacing the task's previous entry)."""
        self.folder.mkdir(exist_ok=True)
        write_json(self.path(entry["task"]), entry)

    def entries(self):
        """Every readable entry, sorted by task id."""
        if not self.folder.is_dir():
            return []
        found = (_read_entry(p) for p in sorted(self.folder.glob("*.json")))
        return [e for e in found if e is not None]

    def write_index(self, job=None):
        """``OUTDIR/manifest.json``: every entry in one file (rebuilt from the entries)."""
        entries = self.entries()
        write_json(self.outdir / "manifest.json",
                   {"rigedit": rigedit_version(), "job": job, "tasks": entries})
        return entries

    def done(self, task, version):
        """True when ``task``'s entry says it succeeded with the same inputs (by content:
        a file whose size and modification time changed is hashed again), settings, target
        and rigedit version, and its outputs are all there as it wrote them (their size and
        modification time): ``--resume`` skips it."""
        entry = self.read(task["id"])
        if entry is None or entry.get("status") != "ok" or entry.get("rigedit") != version:
            return False
        if entry.get("settings") != task["settings"] or entry.get("target") != task["target"]:
            return False
        if entry.get("outputs") != task["outputs"]:
            return False
        stamps = entry.get("output_stamps") or {}
        if not all(stamps.get(o) is not None and quick_stamp(self.outdir / o) == stamps[o]
                   for o in entry["outputs"]):
            return False   # missing, or not as this task wrote it (another batch's since)
        recorded = entry.get("inputs") or {}
        return set(recorded) == set(task["reads"]) and all(
            _same_content(src, recorded[src]) for src in task["reads"])


def _same_content(source, recorded):
    if not isinstance(recorded, dict):
        return False
    stamp = quick_stamp(source)
    if stamp is None:
        return False
    if stamp == recorded.get("stamp"):
        return True
    try:
        return content_hash(source) == recorded.get("hash")
    except OSError:
        return False


def _read_entry(path):
    try:
        if path.stat().st_size > MAX_ENTRY_BYTES:
            return None
        entry = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return None
    if not isinstance(entry, dict) or entry.get("task") != path.stem or not _well_formed(entry):
        return None
    return entry


_STR, _OPT_STR, _DICT = (str,), (str, type(None)), (dict, type(None))
#: The type of each field an entry may have; the report and ``--resume`` rely on them.
_FIELDS = {"job": _STR, "input": _STR, "status": _STR, "target": _OPT_STR,
           "thumbnail": _OPT_STR, "error": _OPT_STR, "failure": _OPT_STR,
           "finished": _OPT_STR, "worker": _OPT_STR, "rigedit": _OPT_STR,
           "inputs": _DICT, "settings": _DICT, "quality": _DICT, "output_stamps": _DICT,
           "seconds": (int, float, type(None))}
_LISTS = ("outputs", "unsure", "warnings")


def _well_formed(entry):
    """Whether every field of ``entry`` has its type (JSON that parses but was edited by
    hand or cut to another shape is no entry: its task runs again, the report shows no
    half row)."""
    if any(k not in entry for k in ("input", "status", "outputs")) \
            or entry["status"] not in ("ok", "failed"):
        return False
    if any(k in entry and not isinstance(entry[k], t) for k, t in _FIELDS.items()):
        return False
    return all(isinstance(entry.get(k, []), list)
               and all(isinstance(v, str) for v in entry.get(k, [])) for k in _LISTS)
