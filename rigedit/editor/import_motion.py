"""Import motion onto the open character: read a motion file, retarget one of its clips onto
the document's skeleton (:func:`rigedit.rigging.retarget_result`), say how well the joint map
covers it, and read or write a joint map. The File menu's dialog
(:class:`~rigedit.ui.import_motion.ImportMotion`) runs these in a worker and adds the clip as
one undo step (:func:`rigedit.editor.clip_commands.add_clip`); no Qt here.
"""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

from ..animation.clip_names import check_clip_name
from ..rigging import load_map, retarget_result, save_map
from ..rigging.retarget.name_map import unmapped_parts
from .files import load_rig

__all__ = ["motion_path", "read_motion", "clip_name", "target_of", "retarget_motion",
           "describe_result", "dropped_because", "load_map", "save_map"]


def motion_path(path):
    """The path :func:`rigedit.load_rig` reads for a chosen file: a rig folder is chosen by
    its ``skeleton.json`` (one file dialog for files and folders), other files as they are."""
    path = Path(path)
    return path.parent if path.name.lower() == "skeleton.json" else path


def read_motion(path):
    """The rig of a motion file (BVH, glTF, rig folder); a BVH's unit guess is expected, so
    the reader's warnings are silenced."""
    return load_rig(path, quiet=True)


def clip_name(path, source_clip, several):
    """The new clip's base name: the motion file's stem (the clip's own name when the file
    holds several), or ``imported motion`` when that is no valid clip name."""
    path = Path(path)
    base = f"{path.stem} {source_clip}" if several else path.stem
    try:
        return check_clip_name(base.strip())
    except ValueError:
        return "imported motion"


def target_of(document):
    """What the retarget reads of the document, as a snapshot a worker may use while the
    user edits on: the skeleton, the clips (a copy of the table) and the binding (so the
    soles are held on the skin; a re-bind replaces it, never edits it)."""
    return SimpleNamespace(skeleton=document.skeleton, clips=dict(document.clips),
                           binding=document.rig.binding)


def retarget_motion(source, clip, target, mapping=None, source_what=None, target_what=None):
    """Retarget clip ``clip`` of rig ``source`` onto ``target`` (:func:`target_of`) with
    ``mapping`` ({motion joint: character joint}; None: the automatic map).

    Returns
    -------
    RetargetResult
        ``clip``, ``mapping`` (the map used), ``target_calibration``, ``facing_note``.

    Raises
    ------
    ValueError
        No legs mapped, a target without legs, a map naming unknown joints.
    """
    return retarget_result(source, clip, target, mapping, source_what=source_what,
                           target_what=target_what)


def describe_result(result, source_skeleton, skeleton, how):
    """How the joint map ``how`` ("automatic", "edited", "from map.json") covers the two
    skeletons, and what ``rigedit retarget`` would warn about.

    Returns
    -------
    summary : str
        Joints mapped, left unmapped, unused; then NOT SURE notes: whole body parts left
        out, a doubtful facing.
    rest : list of str
        The character's joints no motion drives (they keep their rest pose).
    """
    mapped = len(result.mapping)
    summary = (f"joint map {how}, {mapped} mapped, {len(skeleton) - mapped} of this "
               f"character's joints unmapped, {len(source_skeleton) - mapped} of the "
               f"motion's unused")
    driven = set(result.mapping.values())
    rest = [n for n in skeleton.names if n not in driven]
    missing = unmapped_parts(result.target_calibration, [skeleton.index[t] for t in driven])
    doubts = [f"NOT SURE: the map leaves parts unmapped: {'; '.join(missing)}"] if missing \
        else []
    if result.facing_note:
        doubts.append(f"NOT SURE of the facing: {result.facing_note}")
    if doubts:
        summary += ". " + ". ".join(doubts)
    return summary, rest


def dropped_because(document, rig, skeleton):
    """Why a clip retargeted for ``rig`` and ``skeleton`` no longer fits the document
    ("another rig was opened", "the skeleton changed"), or None when it does."""
    if document.rig is not rig:
        return "another rig was opened"
    if document.skeleton is not skeleton:
        return "the skeleton changed"
    return None
