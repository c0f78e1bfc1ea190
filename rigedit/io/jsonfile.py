"""Reading JSON with errors that name the file, and validated access to its values.

Every JSON loader goes through :func:`read_json` and the checkers below, so a value of the
wrong type anywhere (a string where a number belongs, ``"loop": "false"``, a list where a name
belongs) is one ``RigFileError`` "expected ..., got ..." rather than a guess or a crash.

What the reader refuses outright: non-UTF-8 text, ``NaN`` and ``Infinity`` literals, numbers
beyond float range (``1e400``, integers of hundreds of digits), nesting deeper than Python's
parser allows, and a key repeated in one object.
"""
from __future__ import annotations

import json
import math

import numpy as np

from ..errors import RigFileError
from .paths import read_bytes

__all__ = ["read_json", "require", "number", "vector", "numbers", "name", "boolean", "choice",
           "relative_path", "optional", "MAX_MAGNITUDE", "MAX_SECONDS", "MAX_JSON_BYTES"]

#: Bound on coordinates and other magnitudes: a character one million kilometres across is a
#: broken file, and squared the bound stays far inside float range (no overflow in a norm).
MAX_MAGNITUDE = 1e9
#: Bound on times and durations (about 11.6 days).
MAX_SECONDS = 1e6
MAX_JSON_BYTES = 512 * 2**20
MAX_NAME_CHARS = 256


class _Refused(ValueError):
    pass


def _constant(text):
    raise _Refused(f"expected finite numbers, got {text}")


def _float(text):
    value = float(text)
    if not math.isfinite(value):
        raise _Refused(f"expected numbers within float range, got {text[:40]}")
    return value


def _int(text):
    # Python refuses to convert more than 4300 digits (a ValueError of its own); any integer
    # of more than 308 digits is beyond float range anyway.
    if len(text.lstrip("-")) > 308:
        raise _Refused(f"expected numbers within float range, got an integer of "
                       f"{len(text.lstrip('-'))} digits")
    return int(text)


def _pairs(pairs):
    obj = {}
    for key, value in pairs:
        if key in obj:
            raise _Refused(f"key {_short(key)} appears twice in one object")
        obj[key] = value
    return obj


def _short(value, limit=60):
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def read_json(path):
    """Parse a JSON file; ``RigFileError`` naming it when missing, not a regular file or
    malformed."""
    data = read_bytes(path, MAX_JSON_BYTES)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise RigFileError(path, f"expected UTF-8 text, got a byte that is not (at byte "
                                 f"{exc.start})") from None
    if not text.strip():
        raise RigFileError(path, "expected JSON, got an empty file")
    try:
        return json.loads(text, parse_constant=_constant, parse_float=_float, parse_int=_int,
                          object_pairs_hook=_pairs)
    except json.JSONDecodeError as exc:
        raise RigFileError(path, f"malformed JSON at line {exc.lineno}: {exc.msg}") from None
    except _Refused as exc:
        raise RigFileError(path, str(exc)) from None
    except RecursionError:
        raise RigFileError(path, "expected JSON nested a few levels deep, got deeper nesting "
                                 "than the parser allows") from None


def require(path, obj, key, kind, where=""):
    """``obj[key]`` checked to be of ``kind`` (bool never counts as int or float)."""
    if not isinstance(obj, dict):
        raise RigFileError(path, f"expected an object{where}, got {_kind(obj)}")
    if key not in obj:
        raise RigFileError(path, f"expected a {key!r} field{where}, got none")
    value = obj[key]
    kinds = kind if isinstance(kind, tuple) else (kind,)
    if not isinstance(value, kinds) or (isinstance(value, bool) and bool not in kinds):
        names = "/".join(k.__name__ for k in kinds)
        raise RigFileError(path, f"expected {key!r}{where} to be {names}, got {_kind(value)}")
    return value


def optional(obj, key, default):
    """``obj[key]`` when present and not null, else ``default``."""
    value = obj.get(key) if isinstance(obj, dict) else None
    return default if value is None else value


def _kind(value):
    if isinstance(value, bool):
        return f"{str(value).lower()} (a boolean)"
    if isinstance(value, (int, float)):
        return f"{value!r} (a number)"
    if isinstance(value, str):
        return f"{_short(value)} (a string)"
    if value is None:
        return "null"
    return f"{_short(value)} (a{'n object' if isinstance(value, dict) else ' list'})"


def _fail(path, where, text):
    """The error for a checker: ``where`` (a joint, a track) first, then "expected ..."."""
    return RigFileError(path, f"{where}: {text}" if where else text)


def _is_number(value):
    return type(value) in (int, float)  # bool is an int subclass, and not a number here


def number(path, value, what, lo=-MAX_MAGNITUDE, hi=MAX_MAGNITUDE, integer=False, where=""):
    """A number (not a boolean, not a string) within ``[lo, hi]``."""
    if not _is_number(value) or (integer and not isinstance(value, int)):
        raise _fail(path, where, f"expected {what} to be {'an integer' if integer else 'a number'}"
                                 f", got {_kind(value)}")
    if not lo <= value <= hi:
        raise _fail(path, where, f"expected {what} between {lo:g} and {hi:g}, got {value:g}")
    return value


def numbers(path, value, what, width=None, bound=MAX_MAGNITUDE, count=None, where=""):
    """A list of numbers, or of rows of ``width`` numbers, as a float64 array.

    Returns
    -------
    (N,) or (N, width) float64
    """
    ok = isinstance(value, list)
    if ok and width is None:
        ok = all(_is_number(x) for x in value)
    elif ok:
        ok = all(isinstance(r, list) and len(r) == width and all(_is_number(x) for x in r)
                 for r in value)
    if ok and count is not None and len(value) != count:
        ok = False
    if not ok:
        shape = "numbers" if width is None else f"rows of {width} numbers"
        n = "" if count is None else f"{count} "
        raise _fail(path, where, f"expected {what} to be a list of {n}{shape}, got "
                                 f"{_kind(value)}")
    arr = np.array(value, dtype=np.float64).reshape(-1, *(() if width is None else (width,)))
    big = np.abs(arr) > bound
    if big.any():
        raise _fail(path, where, f"expected {what} within +-{bound:g}, got {arr[big][0]:g}")
    return arr


def vector(path, value, n, what, bound=MAX_MAGNITUDE, where=""):
    """Exactly ``n`` numbers, as an (n,) float64 array."""
    return numbers(path, value, what, bound=bound, count=n, where=where)


def name(path, value, what, where="", controls=False):
    """A non-empty string without control characters (no NUL, no newline), of sane length.
    ``controls``: other control characters (a tab) are allowed, only NUL and line breaks are
    not (joint names: the format allows any JSON string and exporters write tabs, but a name
    must stay on the one line of a message or a BVH file)."""
    if not isinstance(value, str) or not value:
        raise _fail(path, where, f"expected {what} to be a non-empty name, got {_kind(value)}")
    if len(value) > MAX_NAME_CHARS:
        raise _fail(path, where, f"expected {what} of at most {MAX_NAME_CHARS} characters, "
                                 f"got {len(value)}")
    bad = next((c for c in value if c in "\0\r\n" or (not controls and (ord(c) < 32 or
                                                                          ord(c) == 127))),
               None)
    if bad is not None:
        raise _fail(path, where, f"expected {what} without control characters, got "
                                 f"{_short(value)}")
    return value


def boolean(path, value, what, where=""):
    """``true`` or ``false`` exactly (the string ``"false"`` is not a boolean)."""
    if not isinstance(value, bool):
        raise _fail(path, where, f"expected {what} to be true or false, got {_kind(value)}")
    return value


def choice(path, value, what, options, where=""):
    """One of ``options`` (strings)."""
    if not isinstance(value, str) or value not in options:
        raise _fail(path, where, f"expected {what} to be one of {', '.join(map(repr, options))}"
                                 f", got {_kind(value)}")
    return value


def relative_path(path, value, what, where=""):
    """A file name relative to the rig folder: a string of sane length, no NUL byte."""
    text = name(path, value, what, where)
    if any(len(part.encode("utf-8", "surrogatepass")) > 255 for part in text.split("/")):
        raise _fail(path, where, f"expected {what} to be a file name of at most 255 bytes per "
                                 f"part, got {_short(text)}")
    return text
