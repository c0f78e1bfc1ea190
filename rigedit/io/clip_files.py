"""Which clip files of a rig folder are rigedit's, and the file each clip is saved to.

A save deletes from ``animations/`` only clip files that are rigedit's:

- those the folder's ``rig.json`` lists under ``"clips"`` (``{name: "animations/FILE.json"}``,
  written by every save), and
- those the saved rig's clips were read from, when they are in this folder
  (the rig-folder reader records them in ``meta.clip_files``, :func:`remember_clip_files`).

A clip file rigedit has no record of that holds a clip of a name being saved becomes that
clip's file (a document recovered after a crash, or saved over a folder it did not come from).

A clip that is deleted or renamed in the editor is therefore gone after the save. Every other
file is left as it is: a README, pictures, a clip file of another name someone copied in after
the rig was loaded (it loads as one more clip next time). A second file holding a clip of a
name being saved is an error (the folder would not load), named in the message, before
anything is written. The rig's own files (``rig.json``, the mesh, ``skeleton.json``,
``weights.npz``) are replaced.
"""
from __future__ import annotations

import json
import stat
from pathlib import Path, PurePosixPath

from ..animation.clip_names import clip_file_stem, name_key
from ..errors import RigFileError

__all__ = ["ANIMATIONS", "CLIP_SUFFIXES", "plan_clip_files", "clip_entry", "remember_clip_files",
           "loaded_clip_files"]

ANIMATIONS = "animations"
#: Clip files: rigedit's JSON clips and compressed clips (``.rgc``, a compressed clip of the
#: rig is saved as one, :mod:`rigedit.io.compressed_file`).
CLIP_SUFFIXES = (".json", ".rgc")

def remember_clip_files(rig, files):
    """Record that ``rig``'s clips were read from ``files`` (``{clip name: path}``), in
    ``rig.meta.clip_files`` (a Rig or a :class:`~rigedit.io.data.RigData`).

    The rig-folder reader records them; code that rebuilds a rig from a copy of it (a recovery
    snapshot) can pass on :func:`loaded_clip_files` of the original, so that a save over the
    original folder still deletes the files of clips deleted since."""
    rig.meta.clip_files = {name: Path(p).resolve() for name, p in files.items()}


def loaded_clip_files(rig):
    """``{clip name: path}`` of the files ``rig``'s clips were read from (empty for a rig
    built in code)."""
    return dict(rig.meta.clip_files)


def clip_entry(rel):
    """``rel`` ("animations/NAME.json") as a file name inside ``animations/``, or None when it
    is anything else (a save never deletes outside ``animations/``)."""
    if not isinstance(rel, str):
        return None
    parts = PurePosixPath(rel).parts
    if (len(parts) == 2 and parts[0] == ANIMATIONS and parts[1].endswith(CLIP_SUFFIXES)
            and parts[1] not in (".", "..") and "\\" not in parts[1]):
        return parts[1]
    return None


def _previous_manifest(folder):
    try:
        data = json.loads((folder / "rig.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def _declared_name(path):
    """The clip name a JSON file declares, or None (unreadable, not a clip)."""
    try:
        # Look before opening: a FIFO or device named like a clip would block the save.
        info = path.stat()
        if not stat.S_ISREG(info.st_mode) or info.st_size > 64 * 2**20:
            return None
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    if isinstance(data, dict) and ("tracks" in data or "keyframes" in data):
        return str(data.get("name") or path.stem)
    return None


def plan_clip_files(folder, rig, names):
    """File names for the clips being saved, and the stale clip files to delete.

    A clip keeps the file it was loaded from or last saved to (``rig.json``'s record). A clip
    file rigedit has no record of that holds a clip of a name being saved is that clip's file
    (a recovered or re-opened document saved over its folder) unless the clip already has
    one. A new or renamed clip gets a file name derived from its name
    (:func:`clip_file_stem`), never one that another file already has.

    Returns
    -------
    files : dict[str, str]
        Clip name -> file name inside ``animations/``.
    stale : list[str]
        File names inside ``animations/`` to delete.

    Raises
    ------
    RigFileError
        A file rigedit has no record of holds a clip of a name being saved that has its own
        file already: the folder would hold that name twice.
    """
    anim = (folder / ANIMATIONS).resolve()
    previous = {}   # clip name -> file name in animations/, for rigedit's files
    recorded = _previous_manifest(folder).get("clips")
    for name, rel in (recorded.items() if isinstance(recorded, dict) else ()):
        file = clip_entry(rel)
        if file is not None:
            previous.setdefault(name, file)
    for name, path in rig.meta.clip_files.items():
        if path.parent == anim:
            previous[name] = path.name
    present = sorted(p.name for p in anim.iterdir()) if anim.is_dir() else []
    on_disk = {name_key(f) for f in present}
    ours = {name_key(f) for f in previous.values()}
    for file in present:
        if name_key(file) in ours or not file.endswith(".json"):
            continue
        declared = _declared_name(anim / file)
        if declared not in names:
            continue
        if declared in previous and name_key(previous[declared]) in on_disk:
            raise RigFileError(anim / file, f"holds a clip {declared!r}, and so does "
                               f"{previous[declared]}, which this save writes: expected one "
                               "file per clip name (move the file away or rename the clip)")
        previous[declared] = file
        ours.add(name_key(file))
    used = {name_key(f) for f in present if name_key(f) not in ours}
    files = {}
    for name in names:   # first the clips that keep their file
        file = previous.get(name)
        if file is not None and name_key(file) not in used:
            files[name] = file
            used.add(name_key(file))
    for name in names:
        if name not in files:
            files[name] = clip_file_stem(name, used) + ".json"
            used.add(name_key(files[name]))
    for name in names:   # a compressed clip is written as .rgc, a plain one as .json
        suffix = ".rgc" if hasattr(rig.clips[name], "blob") else ".json"
        if not files[name].endswith(suffix):
            other = files[name].rsplit(".", 1)[0] + suffix
            if name_key(other) in used:
                other = clip_file_stem(name, used) + suffix
            files[name] = other
            used.add(name_key(other))
    kept = {name_key(f) for f in files.values()}
    stale = sorted(f for f in present if name_key(f) in ours and name_key(f) not in kept
                   and f.endswith(CLIP_SUFFIXES))
    return files, stale


