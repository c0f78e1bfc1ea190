"""Recovery files: where the editor's autosaves and log go, writing, reading and listing
recovery entries, and telling which were left by editors that are no longer running. Pure
Python (no Qt): the timer and the dialog are in :mod:`rigedit.ui.autosave`.

Layout::

    $XDG_CACHE_HOME/rigedit/            (~/.cache/rigedit when XDG_CACHE_HOME is unset)
      rigedit.log                       the editor's error log (tracebacks)
      recovery/
        <pid>-<start>[-<window>]/       one entry per editor (window) running
          <n>/                          one snapshot, n counting up; the highest complete
            rig/                        one wins (a crash while writing n+1 leaves n)
            recovery.json               written last: a snapshot without it is incomplete

``recovery.json`` holds what the rig folder cannot: where the document came from, the
current pose, clip and time. ``<start>`` is the process start time (Linux ``/proc``), so a
later process that happens to get the same pid is not taken for the editor that wrote it.
"""
from __future__ import annotations

import json
import os
import shutil
import time as _time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import RigFileError

__all__ = ["cache_dir", "recovery_dir", "log_path", "entry_folder", "process_alive",
           "is_bundled", "RecoveryEntry", "write_entry", "read_entry", "list_entries",
           "stale_entries", "remove_entry"]

FORMAT = "rigedit.editor.recovery"
_INFO = "recovery.json"


def cache_dir():
    """The user's cache folder for rigedit: ``$XDG_CACHE_HOME/rigedit`` (the XDG base
    directory rule: a relative or empty value is ignored), else ``~/.cache/rigedit``."""
    base = os.environ.get("XDG_CACHE_HOME", "")
    root = Path(base) if base and os.path.isabs(base) else Path.home() / ".cache"
    return root / "rigedit"


def recovery_dir():
    return cache_dir() / "recovery"


def log_path():
    return cache_dir() / "rigedit.log"


def process_start(pid):
    """The start time of process ``pid`` in clock ticks since boot (``/proc/<pid>/stat``
    field 22), or None where /proc cannot tell."""
    try:
        stat = Path(f"/proc/{int(pid)}/stat").read_text()
        return int(stat[stat.rindex(")") + 2:].split()[19])
    except (OSError, ValueError, IndexError):
        return None


def process_alive(pid, start=None):
    """Whether process ``pid`` runs and, when ``start`` is given and /proc can tell, is the
    same process (not a later one that reused the pid). POSIX only: on Windows every entry
    counts as live (so none is offered)."""
    if os.name == "nt":
        return True  # os.kill(pid, 0) would end the process there: never offer, never kill
    try:
        os.kill(int(pid), 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass  # it exists, owned by someone else
    except (OSError, ValueError, OverflowError):
        return False
    now = process_start(pid)
    return start is None or now is None or now == start


def entry_folder(pid=None, window=None):
    """The recovery entry folder of process ``pid`` (this process by default), and of its
    editor window number ``window`` when a process runs several."""
    pid = os.getpid() if pid is None else int(pid)
    name = f"{pid}-{process_start(pid) or 0}"
    return recovery_dir() / (name if window is None else f"{name}-{int(window)}")


def is_bundled(path):
    """Whether ``path`` is one of the bundled characters (read-only: never saved over); the
    one rule is :func:`rigedit.io.rig_save.is_bundled`."""
    from ..io.rig_save import is_bundled as bundled

    return path is not None and bundled(path)


@dataclass
class RecoveryEntry:
    """One editor's recovery entry.

    Attributes
    ----------
    folder : Path
        The entry folder (``recovery/<pid>-<start>``).
    snapshot : Path
        Its newest complete snapshot.
    info : dict
        The snapshot's ``recovery.json``: ``pid``, ``process_start``, ``saved_at`` (seconds
        since the epoch), ``name``, ``original_path`` (str or None), ``bundled``, ``clip``,
        ``time``, ``pose`` ((J, 10) nested lists).
    """

    folder: Path
    snapshot: Path
    info: dict

    @property
    def pid(self):
        return int(self.info.get("pid", -1))

    @property
    def alive(self):
        """Whether the editor that wrote it still runs."""
        return self.pid == os.getpid() or process_alive(self.pid, self.info.get("process_start"))

    def describe(self):
        """One line for the user: the rig, where it came from and when it was saved."""
        when = _time.strftime("%Y-%m-%d %H:%M", _time.localtime(self.info.get("saved_at", 0)))
        origin = "bundled character" if self.info.get("bundled") else \
            self.info.get("original_path") or "never saved"
        return f"{self.info.get('name', 'rig')} ({origin}), autosaved {when}"


def _snapshots(folder):
    """Complete snapshots of an entry folder, newest first."""
    nums = []
    for p in folder.iterdir() if folder.is_dir() else ():
        if p.name.isdigit() and (p / _INFO).is_file():
            nums.append(int(p.name))
    return [folder / str(n) for n in sorted(nums, reverse=True)]


def write_entry(rig, pose, clip=None, time=0.0, original_path=None, folder=None):
    """Write a snapshot of the document to this process's recovery entry.

    Parameters
    ----------
    rig : Rig
        Written with :func:`rigedit.io.rig_folder.save_rig_folder` (mesh, skeleton, weights,
        clips).
    pose : (J, 10) float64
        The current pose (:meth:`Pose.as_array`).
    clip : str or None
        The current clip's name.
    time : float
        The current time, seconds.
    original_path : path or None
        Where the document was opened from (its Save goes there after recovery).
    folder : path, optional
        The entry folder; this process's by default.

    Returns
    -------
    Path
        The snapshot written. Older snapshots of the entry are removed once it is complete.
    """
    from ..io.atomic import write_json
    from ..io.rig_folder import save_rig_folder
    from ..io.rig_save import loaded_clip_files

    folder = Path(folder) if folder is not None else entry_folder()
    folder.mkdir(parents=True, exist_ok=True)
    numbered = [int(p.name) for p in folder.iterdir() if p.name.isdigit()]
    snap = folder / str(max(numbered, default=0) + 1)
    pose = np.asarray(pose, dtype=np.float64)
    if pose.shape != (len(rig.skeleton), 10):
        raise ValueError(f"expected a pose of {len(rig.skeleton)} joints, got {pose.shape}")
    snap.mkdir()
    save_rig_folder(snap / "rig", rig)
    pid_text, start_text = (folder.name.split("-") + [""])[:2]
    write_json(snap / _INFO, {
        "format": FORMAT, "version": 1,
        "pid": int(pid_text) if pid_text.isdigit() else os.getpid(),
        "process_start": int(start_text) if start_text.isdigit() and int(start_text) else None,
        "saved_at": _time.time(), "name": rig.name,
        "original_path": None if original_path is None else str(original_path),
        "bundled": is_bundled(original_path),
        "clip": clip, "time": float(time), "pose": pose.tolist(),
        # the original folder's clip files, so that saving the recovered document there
        # still deletes the files of clips deleted before the crash
        "clip_files": {n: str(p) for n, p in loaded_clip_files(rig).items()}})
    for old in folder.iterdir():
        if old != snap:
            _remove(old)
    return snap


def read_entry(entry):
    """Load a recovery entry's rig and state.

    Returns
    -------
    rig : Rig
        ``rig.path`` is the original folder, or None when there was none or it was a
        bundled character (so that Save asks where to save).
    pose : (J, 10) float64
    clip : str or None
    time : float

    Raises
    ------
    RigFileError
        When the snapshot is unreadable.
    """
    from ..io.rig_folder import load_rig_folder
    from ..io.rig_save import remember_clip_files

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig = load_rig_folder(entry.snapshot / "rig")
    info = entry.info
    try:
        pose = np.asarray(info["pose"], dtype=np.float64)
    except (KeyError, TypeError, ValueError) as exc:
        raise RigFileError(entry.snapshot / _INFO, f"expected a pose, got {exc}") from None
    if pose.shape != (len(rig.skeleton), 10) or not np.all(np.isfinite(pose)):
        raise RigFileError(entry.snapshot / _INFO,
                           f"expected a finite pose of {len(rig.skeleton)} joints")
    original = info.get("original_path")
    rig.path = None if original is None or info.get("bundled") else Path(original)
    rig.name = str(info.get("name", rig.name))
    files = info.get("clip_files")
    if rig.path is not None and isinstance(files, dict) and all(
            isinstance(v, str) for v in files.values()):
        remember_clip_files(rig, files)
    clip = info.get("clip")
    return rig, pose, clip if clip in rig.clips else None, float(info.get("time", 0.0))


def list_entries():
    """Every recovery entry with a complete snapshot, newest first."""
    entries = []
    root = recovery_dir()
    for folder in root.iterdir() if root.is_dir() else ():
        for snap in _snapshots(folder)[:1]:
            try:
                info = json.loads((snap / _INFO).read_text(encoding="utf-8"))
            except (OSError, ValueError):
                continue
            if isinstance(info, dict) and info.get("format") == FORMAT:
                entries.append(RecoveryEntry(folder, snap, info))
    return sorted(entries, key=lambda e: e.info.get("saved_at", 0), reverse=True)


def stale_entries():
    """Entries left by editors that no longer run (those to offer for recovery)."""
    return [e for e in list_entries() if not e.alive]


def remove_entry(folder):
    """Delete a recovery entry folder (no error when it is already gone)."""
    _remove(Path(folder))


def _remove(path):
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        try:
            path.unlink()
        except FileNotFoundError:
            pass
