"""glTF JSON -> pygltflib objects, built directly (pygltflib's generic decoder is slow), and
pygltflib itself imported on the first glTF read."""
from __future__ import annotations

import dataclasses
import typing

__all__ = ["lib", "decode"]

_HINTS = {}


def lib():
    """pygltflib, imported on the first glTF read rather than with the format registry
    (:mod:`rigedit.io.registry`): a process that opens only rig folders saves its ~0.07 s."""
    import pygltflib

    return pygltflib


def _field_types(cls):
    """{field name: dataclass type (or None), is a list} of one pygltflib class, cached."""
    if cls not in _HINTS:
        hints = typing.get_type_hints(cls)
        out = {}
        for f in dataclasses.fields(cls):
            hint, many = hints.get(f.name), False
            for _ in range(3):  # unwrap Optional[...] and List[...]
                args = [a for a in typing.get_args(hint) if a is not type(None)]
                if typing.get_origin(hint) in (list, typing.List):
                    many = True
                if not args:
                    break
                hint = args[0]
            out[f.name] = (hint if dataclasses.is_dataclass(hint) or hint is lib().Attributes
                           else None, many)
        _HINTS[cls] = out
    return _HINTS[cls]


def decode(cls, data):
    """A pygltflib object from parsed JSON: the same objects as ``GLTF2.from_json`` builds,
    built directly (pygltflib's generic decoder took 0.6 s for CesiumMan's 300 objects, which
    would grow to many seconds for a character with dozens of clips). Unknown keys are
    dropped, missing ones keep pygltflib's defaults."""
    attributes = lib().Attributes
    if cls is attributes:
        return attributes(**data) if isinstance(data, dict) else data
    if not isinstance(data, dict):
        raise TypeError(f"expected an object for {cls.__name__}, got {type(data).__name__}")
    kwargs = {}
    for key, (sub, many) in _field_types(cls).items():
        if key not in data:
            continue
        value = data[key]
        if sub is not None and value is not None:
            value = [decode(sub, v) for v in value] if many else decode(sub, value)
        kwargs[key] = value
    return cls(**kwargs)
