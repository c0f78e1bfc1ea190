"""FBX in: opening a file with ``ufbx`` safely, and reading its objects without crashing.

Two things about the ``ufbx`` Python binding (0.0.5) shape this module:

- **Its reference counts are wrong.** A list returns an element it made before without a
  new reference (and more objects come back a reference short): fetching
  ``scene.nodes[1].name`` twice, or ``mesh.vertices`` again after dropping the first result,
  is a segmentation fault, and so, at random (1 run in 10 of four reads of mixamo.fbx), is
  freeing a read's objects in any order. :class:`Held` therefore fetches every attribute
  once and keeps it, and every ufbx wrapper fetched is pinned (:func:`_pin`): never freed.
  That leaks the wrappers and the ufbx scene of each read (about 30 MB for mixamo.fbx) until
  the process ends, the price of never crashing. The readers touch ufbx objects only
  through :class:`Held`.
- **It exposes no allocator limits** (ufbx's ``temp_allocator`` / ``result_allocator``
  memory and allocation limits are not among ``LoadOpts``; unknown keywords are ignored
  silently). The bound on what a file can make ufbx allocate is therefore checked before
  ufbx sees it (:mod:`rigedit.io.fbx_read_limits`), and ufbx is given only bytes
  (``load_memory`` with ``load_external_files=False``), so it never opens another file.
"""
from __future__ import annotations

import ctypes
import re
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from ..errors import RigFileError
from .fbx_read_limits import check_claims
from .paths import read_bytes

__all__ = ["Held", "open_scene", "opened", "release", "call", "matrix_of", "target_axes",
           "NODE_DEPTH_LIMIT"]

#: Deeper node hierarchies are refused (ufbx's ``node_depth_limit``).
NODE_DEPTH_LIMIT = 1000

_BUFFER_LISTS = ("Vec2List", "Vec3List", "Vec4List")
_PLAIN = (int, float, str, bytes, bool, tuple, type(None))


def ufbx_module():
    """The ``ufbx`` module, imported on first use (only FBX reading needs it)."""
    import ufbx

    return ufbx


class Keep(list):
    """The wrappers a read fetched (and its :class:`Held` objects)."""


def _pin(value):
    """Give a ufbx wrapper one reference of its own, never returned: the binding returns
    some objects with a reference too few (a list hands out an element it made before
    without a new one: ``sys.getrefcount`` does not grow when ``scene.nodes[1]`` is indexed
    twice), so counting them right is not possible from here; a wrapper pinned once per
    fetch is never freed, so never freed while in use or in the wrong order."""
    ctypes.pythonapi.Py_IncRef(ctypes.py_object(value))


def _hold(value, keep):
    """``value`` made safe to keep: plain data as it is, a ufbx list as a numpy array or a
    list of held items, another ufbx object as a :class:`Held`; the wrapper kept alive."""
    if isinstance(value, _PLAIN) or not type(value).__module__.startswith("ufbx"):
        return value
    keep.append(value)
    _pin(value)
    kind = type(value).__name__
    if kind in _BUFFER_LISTS:
        return np.array(memoryview(value), dtype=np.float64)   # a copy, owned by numpy
    if kind.endswith("List"):
        items = list(value)
        if items and isinstance(items[0], _PLAIN):   # a list of numbers or named tuples
            return items
        return [_hold(item, keep) for item in items]
    if callable(value):
        return lambda *args, **kw: _hold(value(*[_raw(a) for a in args], **kw), keep)
    return Held(value, keep)


def _raw(value):
    return value._obj if isinstance(value, Held) else value


class Held:
    """A ufbx object whose attributes are each fetched once and kept (see the module's
    docstring): ``held.name``, ``held.children`` (a list of :class:`Held`),
    ``held.vertices`` ((N, 3) float64 for ufbx's vector lists). ``raw`` is the wrapper
    itself."""

    __slots__ = ("_obj", "_cache", "_keep")

    def __init__(self, obj, keep):
        self._obj, self._cache, self._keep = obj, {}, keep
        keep.append(self)        # so that release() can drop its wrappers whoever holds it

    def _drop(self):
        self._obj, self._cache = None, {}

    @property
    def raw(self):
        return self._obj

    def __getattr__(self, name):
        cache = self._cache
        if name not in cache:
            cache[name] = _hold(getattr(self._obj, name), self._keep)
        return cache[name]


def release(keep):
    """End a read: every :class:`Held` lets go of what it fetched (a traceback or a caller
    may still hold one) and ``keep`` is emptied. The ufbx wrappers themselves stay (pinned,
    see :func:`_pin`): freeing them crashes the binding at random, whatever the order."""
    for item in keep:
        if isinstance(item, Held):
            item._drop()
    keep.clear()


@contextmanager
def opened(path, convert=True):
    """``with opened(path) as scene:`` :func:`open_scene` and :func:`release` around a
    block (a held scene whose ``keep`` is ``scene._keep``)."""
    scene, keep = open_scene(path, convert)
    try:
        yield scene
    finally:
        del scene
        release(keep)


def call(function, *args, keep, **kwargs):
    """``function(*args, **kwargs)`` (a function of the ufbx module) with held arguments
    unwrapped and the result held in ``keep``."""
    return _hold(function(*[_raw(a) for a in args], **kwargs), keep)


def matrix_of(m):
    """(4, 4) float64 of a ufbx ``Matrix`` (four column vectors, the last the
    translation)."""
    out = np.eye(4)
    out[:3, :4] = np.array([tuple(m.c0), tuple(m.c1), tuple(m.c2), tuple(m.c3)],
                           dtype=np.float64).T
    return out


def target_axes():
    """rigedit's frame as ufbx axes: Y up, +Z forward (the character faces +Z),
    right-handed, so +X is the character's left... as glTF's (ufbx's ``axes_right_handed_
    y_up``)."""
    ufbx = ufbx_module()
    a = ufbx.CoordinateAxis
    return ufbx.CoordinateAxes(right=a.POSITIVE_X, up=a.POSITIVE_Y, front=a.POSITIVE_Z)


def _options(path):
    ufbx = ufbx_module()
    return dict(
        load_external_files=False,              # textures are read by rigedit, from the folder
        ignore_missing_external_files=True,
        node_depth_limit=NODE_DEPTH_LIMIT,
        target_axes=target_axes(), target_unit_meters=1.0,
        # lengths in the vertices and node transforms themselves: no root scale node
        space_conversion=ufbx.SpaceConversion.MODIFY_GEOMETRY,
        geometry_transform_handling=ufbx.GeometryTransformHandling.MODIFY_GEOMETRY,
        inherit_mode_handling=ufbx.InheritModeHandling.COMPENSATE,
        clean_skin_weights=True,                # sorted by weight, zeros dropped
        generate_missing_normals=True,
        filename=str(path))


def open_scene(path, convert=True):
    """Load the FBX file ``path`` with ufbx, converted to metres, Y up, +Z forward (as the
    file is when ``convert`` is False).

    Returns
    -------
    scene : Held
        The scene (see :class:`Held`).
    keep : list
        Every wrapper fetched (and every :class:`Held`); the caller passes it to
        :func:`release` when its read is done, also when it failed.

    Raises
    ------
    RigFileError
        Not a regular file, too large, an array claim beyond the bounds, or any ufbx error
        (truncated, corrupt, unsupported version, too deep), naming the file.
    """
    path = Path(path)
    data = read_bytes(path)
    check_claims(data, path)
    ufbx = ufbx_module()
    try:
        options = _options(path) if convert else dict(load_external_files=False,
                                                       filename=str(path))
        raw = ufbx.load_memory(data, **options)
    except ufbx.UfbxError as exc:
        raise RigFileError(path, f"expected a valid FBX file, got one ufbx cannot read "
                                 f"({_ufbx_problem(exc)})") from None
    except (MemoryError, OverflowError) as exc:
        raise RigFileError(path, f"expected an FBX file rigedit can hold in memory, got "
                                 f"one that does not fit ({type(exc).__name__})") from None
    keep = Keep()
    keep.append(raw)
    _pin(raw)
    return Held(raw, keep), keep


def _ufbx_problem(exc):
    """A phrase for a ufbx error: its kind (``TruncatedFileError`` -> "truncated file"),
    and its text where that says more than "Failed to load"."""
    kind = type(exc).__name__.removesuffix("Error")
    words = re.sub(r"(?<!^)(?=[A-Z])", " ", kind).lower()
    text = (str(exc).strip().splitlines() or [""])[0]
    if not text or text.lower() in ("failed to load", words):
        return words if kind not in ("Unknown", "Ufbx") else "failed to load"
    return f"{words}: {text}" if kind not in ("Unknown", "Ufbx") else text


def axes_text(axes):
    """``"+X right, +Z up, -Y front"`` of ufbx ``CoordinateAxes``."""
    names = {0: "+X", 1: "-X", 2: "+Y", 3: "-Y", 4: "+Z", 5: "-Z"}
    return (f"{names.get(int(axes.right), '?')} right, {names.get(int(axes.up), '?')} up, "
            f"{names.get(int(axes.front), '?')} front")
