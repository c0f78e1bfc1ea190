"""Joint map files: a JSON object ``{source joint: target joint}``, read and checked, written
atomically."""
from __future__ import annotations

import json

from ...errors import RigFileError

__all__ = ["load_map", "save_map"]


def load_map(path, src_skeleton=None, tgt_skeleton=None):
    """Read a JSON joint map ``{source_joint: target_joint}``; with skeletons, check that every
    name exists (``RigFileError`` naming the file and the joint)."""
    try:
        with open(path, encoding="utf-8") as fh:
            data = json.load(fh)
    except OSError as exc:
        raise RigFileError(path, f"cannot read the joint map ({exc.strerror})") from None
    except ValueError as exc:
        raise RigFileError(path, f"expected a JSON joint map, got invalid JSON ({exc})") \
            from None
    if isinstance(data, dict) and isinstance(data.get("map"), dict):
        data = data["map"]
    if not isinstance(data, dict) or not all(isinstance(k, str) and isinstance(v, str)
                                             for k, v in data.items()):
        raise RigFileError(path, f"expected an object {{source joint: target joint}} of "
                           f"names, got {type(data).__name__}")
    for names, sk, role in ((data.keys(), src_skeleton, "source"),
                            (data.values(), tgt_skeleton, "target")):
        if sk is not None:
            for nm in names:
                if nm not in sk.index:
                    raise RigFileError(path, f"{role} joint {nm!r} is not in the {role} "
                                       f"skeleton")
    if len(set(data.values())) != len(data):
        raise RigFileError(path, "expected each target joint once, got a repeat")
    return dict(data)


def save_map(path, mapping):
    """Write a joint map as JSON ``{source joint: target joint}``, atomically."""
    from ...io.atomic import write_json

    write_json(path, dict(mapping))
