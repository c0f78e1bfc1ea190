"""BVH text -> plain arrays: the HIERARCHY by a descent with its own stack (a file nested
10,000 joints deep is read, not a RecursionError; line numbers for errors), the MOTION block
in one pass of numpy's C reader. No units, no rig: see :mod:`rigedit.io.bvh` for what the
numbers mean.

Counts (``CHANNELS n``, ``Frames: n``) are ASCII digits only (``int()`` would take ``'³'`` or
``'３'`` and fail later), and every number is within :data:`MAX_VALUE` in magnitude: a figure
larger than that (a million kilometres in millimetres) overflows float32 skinning once
squared or multiplied through a chain, and its export would not load back.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..errors import RigFileError

__all__ = ["parse_bvh", "CHANNEL_AXES", "MAX_VALUE", "MAX_DEPTH"]

#: Bound on every OFFSET and channel value (file units or degrees).
MAX_VALUE = 1e9
#: Joints nested deeper than this are refused (no figure has a chain of a thousand bones;
#: the skeleton's own walks stay fast below it).
MAX_DEPTH = 1000
_COUNT = re.compile(r"[0-9]{1,9}")  # ASCII digits only

#: Channel names (lower case) -> (kind, axis index).
CHANNEL_AXES = {f"{a}{kind}": (kind, i) for i, a in enumerate("xyz")
                for kind in ("position", "rotation")}


class _Joint:
    __slots__ = ("name", "parent", "offset", "channels", "end", "line")

    def __init__(self, name, parent, line):
        self.name, self.parent, self.line = name, parent, line
        self.offset = None
        self.channels = []
        self.end = None


class _Tokens:
    """Tokens of the HIERARCHY block with their line numbers (braces split off)."""

    def __init__(self, path, lines):
        self.path = path
        self.items = [(tok, n + 1) for n, line in enumerate(lines)
                      for tok in re.findall(r"[{}]|[^\s{}]+", line)]
        self.pos = 0

    def error(self, problem, line=None):
        if line is None:
            line = self.items[min(self.pos, len(self.items) - 1)][1] if self.items else 1
        return RigFileError(self.path, f"line {line}: {problem}")

    def peek(self):
        return self.items[self.pos][0] if self.pos < len(self.items) else None

    def next(self, what):
        if self.pos >= len(self.items):
            raise self.error(f"expected {what}, got the end of the hierarchy (a '{{' without "
                             f"its '}}'?)")
        tok, line = self.items[self.pos]
        self.pos += 1
        return tok, line

    def expect(self, word):
        tok, line = self.next(repr(word))
        if tok.lower() != word.lower():
            raise self.error(f"expected {word!r}, got {tok!r}", line)
        return line

    def floats(self, n, what):
        out = []
        for _ in range(n):
            tok, line = self.next(f"{n} numbers after {what}")
            try:
                out.append(float(tok))
            except ValueError:
                raise self.error(f"expected {n} numbers after {what}, got {tok!r}", line) from None
        arr = np.array(out)
        if not np.all(np.isfinite(arr)):
            raise self.error(f"expected finite numbers after {what}, got {tok!r}", line)
        if np.any(np.abs(arr) > MAX_VALUE):
            raise self.error(f"expected numbers within +-{MAX_VALUE:g} after {what}, got "
                             f"{arr[np.abs(arr) > MAX_VALUE][0]:g}", line)
        return arr

    def name_until_brace(self, what):
        words = []
        while self.peek() not in (None, "{"):
            words.append(self.next(what)[0])
        if not words:
            raise self.error(f"expected a {what}, got {self.peek()!r}")
        return " ".join(words)


def _open_joint(tok, joints, parent, line, stack):
    if len(stack) >= MAX_DEPTH:
        raise tok.error(f"expected joints nested at most {MAX_DEPTH} deep, got deeper", line)
    joint = _Joint(tok.name_until_brace("joint name"), parent, line)
    joints.append(joint)
    tok.expect("{")
    stack.append(joint)


def _channels(tok, joint):
    count_tok, cline = tok.next("a channel count")
    if not _COUNT.fullmatch(count_tok):
        raise tok.error(f"expected a channel count (digits 0-9), got {count_tok!r}", cline)
    for _ in range(int(count_tok)):
        name, nline = tok.next(f"{count_tok} channel names")
        if name.lower() not in CHANNEL_AXES:
            raise tok.error(f"expected a channel name (Xposition ... Zrotation), "
                            f"got {name!r}", nline)
        joint.channels.append(CHANNEL_AXES[name.lower()])


def _parse_joint(tok, joints, parent, line):
    """A ROOT block and every joint below it, with an explicit stack of open joints."""
    stack = []
    _open_joint(tok, joints, parent, line, stack)
    while stack:
        joint = stack[-1]
        word, wline = tok.next("OFFSET, CHANNELS, JOINT, End Site or '}'")
        key = word.upper()
        if key == "OFFSET":
            joint.offset = tok.floats(3, "OFFSET")
        elif key == "CHANNELS":
            _channels(tok, joint)
        elif key == "JOINT":
            _open_joint(tok, joints, joint, wline, stack)
        elif key == "END":
            tok.expect("Site")
            tok.expect("{")
            tok.expect("OFFSET")
            joint.end = tok.floats(3, "OFFSET")
            tok.expect("}")
        elif word == "}":
            if joint.offset is None:
                raise tok.error(f"expected an OFFSET in joint {joint.name!r}, got none",
                                joint.line)
            stack.pop()
        else:
            raise tok.error(f"expected OFFSET, CHANNELS, JOINT, End Site or '}}' in joint "
                            f"{joint.name!r}, got {word!r}", wline)


def _parse_hierarchy(path, lines):
    tok = _Tokens(path, lines)
    tok.expect("HIERARCHY")
    joints = []
    while tok.peek() is not None:
        word, line = tok.next("ROOT")
        if word.upper() != "ROOT":
            raise tok.error(f"expected ROOT or MOTION, got {word!r}", line)
        _parse_joint(tok, joints, None, line)
    if not joints:
        raise tok.error("expected a ROOT joint, got none")
    return joints


def _header_value(path, lines, i, label, integer=False):
    if i >= len(lines) or not lines[i].strip().lower().startswith(label.lower()):
        got = repr(lines[i].strip()[:40]) if i < len(lines) else "the end of the file"
        raise RigFileError(path, f"line {i + 1}: expected '{label}', got {got}")
    text = lines[i].strip()[len(label):].strip()
    if integer:
        if not _COUNT.fullmatch(text):
            raise RigFileError(path, f"line {i + 1}: expected a number after '{label}' (a frame "
                                     f"count in digits 0-9), got {text[:40]!r}")
        return int(text)
    try:
        return float(text)
    except ValueError:
        raise RigFileError(path, f"line {i + 1}: expected a number after '{label}', "
                                 f"got {text[:40]!r}") from None


def _frame_rows(lines, first):
    """(rows, line numbers) of the non-blank lines from ``first``: the slow path, for errors."""
    rows = [(n + 1, line.split()) for n, line in enumerate(lines[first:], start=first)]
    return [r for _, r in rows if r], [n for n, r in rows if r]


def _diagnose_frames(path, lines, first, frames, num_channels):
    """Raise the RigFileError that describes what is wrong with the frame lines."""
    rows, numbers = _frame_rows(lines, first)
    if len(rows) != frames:
        raise RigFileError(path, f"expected {frames} frame lines after line {first}, "
                                 f"got {len(rows)}")
    for row, line in zip(rows, numbers):
        if len(row) != num_channels:
            raise RigFileError(path, f"line {line}: expected {num_channels} numbers (one per "
                                     f"channel), got {len(row)}")
        for word in row:
            try:
                float(word)
            except ValueError:
                raise RigFileError(path, f"line {line}: expected numbers, got {word!r}") \
                    from None
    raise RigFileError(path, f"expected {frames} lines of {num_channels} numbers after line "
                             f"{first}")


def _parse_motion(path, lines, start, num_channels):
    """(N, C) frame values and the frame time, from the lines after ``MOTION``."""
    i = start
    frames = _header_value(path, lines, i, "Frames:", integer=True)
    frame_time = _header_value(path, lines, i + 1, "Frame Time:")
    if not frame_time > 0 or not np.isfinite(frame_time) or frame_time > 3600:
        raise RigFileError(path, f"line {i + 2}: expected a Frame Time > 0 seconds (at most "
                                 f"an hour), got {frame_time:g}")
    first = i + 2
    if frames == 0 or num_channels == 0:
        _, numbers = _frame_rows(lines, first)
        if numbers and num_channels:
            raise RigFileError(path, f"line {numbers[0]}: expected no frame lines (Frames: 0), "
                                     f"got some")
        # Frames: 0 is a skeleton without motion (read_bvh gives no clip); without channels
        # the frames hold nothing either
        return np.zeros((0, num_channels)), frame_time
    # numpy's C reader: one pass over the block (blank lines skipped); errors are then
    # located line by line on the slow path
    try:
        data = np.loadtxt(lines[first:], dtype=np.float64, ndmin=2, comments=None)
    except ValueError:
        data = None
    if data is None or data.shape != (frames, num_channels):
        _diagnose_frames(path, lines, first, frames, num_channels)
    bad = ~np.all(np.isfinite(data), axis=1)
    if bad.any():
        line = _frame_rows(lines, first)[1][int(np.flatnonzero(bad)[0])]
        raise RigFileError(path, f"line {line}: expected finite numbers, got NaN or inf")
    big = np.any(np.abs(data) > MAX_VALUE, axis=1)
    if big.any():
        line = _frame_rows(lines, first)[1][int(np.flatnonzero(big)[0])]
        raise RigFileError(path, f"line {line}: expected channel values within "
                                 f"+-{MAX_VALUE:g}, got {np.abs(data[big]).max():g}")
    return data, frame_time


def parse_bvh(path, text=None):
    """Parse a BVH file into plain data (file units, no conversion).

    Returns
    -------
    dict with ``names`` (list[str], depth-first), ``parents`` ((J,) int), ``offsets``
    ((J, 3) float64), ``channels`` (list of [(kind, axis), ...] per joint, kind "position" or
    "rotation", axis 0-2), ``ends`` (list of (3,) offset or None), ``frames`` ((N, C)
    float64, C the total channel count), ``frame_time`` (float, seconds).

    Raises
    ------
    RigFileError
        Naming the file and, where it helps, the line.
    """
    path = Path(path)
    if text is None:
        try:
            text = path.read_text(encoding="utf-8-sig", errors="replace")
        except OSError as exc:
            raise RigFileError(path, f"expected a readable file, got {exc.strerror or exc}") \
                from None
    lines = text.splitlines()
    motion = next((n for n, line in enumerate(lines) if line.strip().upper() == "MOTION"), None)
    if motion is None:
        raise RigFileError(path, "expected a MOTION section, got none")
    joints = _parse_hierarchy(path, lines[:motion])
    index = {}
    for j, joint in enumerate(joints):
        if joint.name in index:
            raise RigFileError(path, f"line {joint.line}: expected unique joint names, got "
                                     f"{joint.name!r} twice")
        index[joint.name] = j
    num_channels = sum(len(j.channels) for j in joints)
    frames, frame_time = _parse_motion(path, lines, motion + 1, num_channels)
    return {"names": [j.name for j in joints],
            "parents": np.array([-1 if j.parent is None else index[j.parent.name]
                                 for j in joints], dtype=np.int64),
            "offsets": np.array([j.offset for j in joints]),
            "channels": [j.channels for j in joints], "ends": [j.end for j in joints],
            "frames": frames, "frame_time": frame_time}
