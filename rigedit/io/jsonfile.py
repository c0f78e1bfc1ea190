"""Reading JSON with errors that name the file."""
from __future__ import annotations

import json
from pathlib import Path

from ..errors import RigFileError

__all__ = ["read_json", "require"]


def read_json(path):
    """Parse a JSON file; ``RigFileError`` naming it when missing or malformed."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise RigFileError(path, "file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise RigFileError(path, f"cannot read: {exc}") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise RigFileError(path, f"malformed JSON at line {exc.lineno}: {exc.msg}") from None


def require(path, obj, key, kind, where=""):
    """``obj[key]`` checked to be of ``kind``; ``RigFileError`` otherwise."""
    if not isinstance(obj, dict) or key not in obj:
        raise RigFileError(path, f"expected a {key!r} field{where}, got none")
    value = obj[key]
    if not isinstance(value, kind):
        names = kind.__name__ if isinstance(kind, type) else "/".join(k.__name__ for k in kind)
        raise RigFileError(path, f"expected {key!r}{where} to be {names}, got "
                                 f"{type(value).__name__}")
    return value
