"""Clip names: what a name may hold, and the file name a rig folder stores it under.

A clip name is shown to the user and written inside the clip's file; the file's own name is
derived from it (:func:`clip_file_stem`) so that any valid name gives a portable file name.

Rules (checked where a name is made: :class:`~rigedit.animation.clip.Clip`, the editor's new /
rename / duplicate, the clip loaders):

- a string of 1 to :data:`MAX_NAME_LENGTH` characters, not only spaces, without leading or
  trailing spaces;
- no ``/`` or ``\\`` (a name is not a path), no control characters (NUL, newline, tab, ...),
  no line or paragraph separators;
- not ``.`` or ``..``.

Uniqueness: within a rig, names are compared ignoring case (:func:`name_key`) when the editor
makes one, because ``Walk`` and ``walk`` would be one file on a case-insensitive file system
(macOS, Windows) and are easy to confuse. A folder that already holds both still loads: their
file names are kept apart by :func:`clip_file_stem`.
"""
from __future__ import annotations

import unicodedata

__all__ = ["MAX_NAME_LENGTH", "check_clip_name", "check_new_clip_name", "name_key",
           "clip_file_stem"]

MAX_NAME_LENGTH = 128
#: Characters a Windows file name cannot hold (the others are already refused in names).
_NOT_IN_FILE_NAMES = '<>:"|?*'
_RESERVED_STEMS = {"con", "prn", "aux", "nul", *(f"com{i}" for i in range(10)),
                   *(f"lpt{i}" for i in range(10))}
#: UTF-8 bytes of a derived file stem: file systems allow 255 per name, with room for
#: ``-NN.json``.
_MAX_STEM_BYTES = 200


def check_clip_name(name):
    """Return ``name`` when it is a valid clip name, else raise ``ValueError`` naming it.

    Parameters
    ----------
    name : str

    Returns
    -------
    name : str
    """
    if not isinstance(name, str):
        raise ValueError(f"clip name {name!r}: expected a string, got {type(name).__name__}")
    problem = None
    if not name.strip():
        problem = "expected a non-empty name, got " + ("spaces only" if name else "nothing")
    elif name != name.strip():
        problem = "expected no leading or trailing spaces"
    elif len(name) > MAX_NAME_LENGTH:
        problem = f"expected at most {MAX_NAME_LENGTH} characters, got {len(name)}"
    elif "/" in name or "\\" in name:
        problem = "expected no '/' or '\\' (a clip name is not a path)"
    elif name in (".", ".."):
        problem = "expected a name, got a folder reference"
    else:
        bad = next((c for c in name if unicodedata.category(c) in ("Cc", "Zl", "Zp")), None)
        if bad is not None:
            problem = f"expected no control characters, got {bad!r}"
    if problem:
        raise ValueError(f"clip name {name[:80]!r}: {problem}")
    return name


def name_key(name):
    """The form two names are compared in for uniqueness: case-folded, NFC-normalised."""
    return unicodedata.normalize("NFC", name).casefold()


def check_new_clip_name(name, existing, old=None):
    """Validate a name the editor is about to give a clip.

    Parameters
    ----------
    name : str
    existing : iterable of str
        The rig's clip names.
    old : str, optional
        The clip's current name when renaming (a change of case only is allowed).

    Returns
    -------
    name : str

    Raises
    ------
    ValueError
        Invalid, or equal ignoring case to another clip's name.
    """
    check_clip_name(name)
    key = name_key(name)
    for other in existing:
        if other != old and name_key(other) == key:
            raise ValueError(f"clip name {name!r}: expected a new name, got "
                             + ("the same" if other == name else f"the same as {other!r} "
                                "ignoring case"))
    return name


def clip_file_stem(name, taken=()):
    """A file name stem (without ``.json``) for clip ``name``, portable to Windows and macOS.

    Characters Windows refuses become ``_``, a leading dot (a hidden file) or a reserved
    device name (``CON``, ``NUL``, ...) gets a ``_`` in front, trailing dots and spaces go,
    and the stem is cut to 200 UTF-8 bytes. A stem whose :func:`name_key` is in ``taken`` gets
    ``-2``, ``-3``, ... appended.

    Parameters
    ----------
    name : str
        A valid clip name.
    taken : collection of str
        Keys (:func:`name_key`) of the file names already used, with ``.json``.

    Returns
    -------
    stem : str
    """
    stem = "".join("_" if c in _NOT_IN_FILE_NAMES else c for c in name).rstrip(". ")
    stem = stem.encode("utf-8")[:_MAX_STEM_BYTES].decode("utf-8", "ignore").rstrip(". ")
    if not stem or stem.startswith(".") or stem.split(".")[0].lower() in _RESERVED_STEMS:
        stem = "_" + stem
    candidate, i = stem, 2
    while name_key(candidate + ".json") in taken:
        candidate, i = f"{stem}-{i}", i + 1
    return candidate
