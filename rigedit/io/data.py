"""The plain record every reader returns and every writer takes: :class:`RigData`.

A reader turns a file into arrays and a few facts (:class:`RigMeta`) and stops there: it does
not build a :class:`rigedit.rig.Rig`, so it never starts a weights solve. ``Rig.from_data``
(above io) builds the rig and decides, in the open, whether weights are computed.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

from rigedit.model.morph import MorphTargets

__all__ = ["RigData", "RigMeta", "WeightsComputedWarning", "as_rig_data", "build_rig",
           "register_rig_builder"]


class WeightsComputedWarning(UserWarning):
    """A rig had no weights file, so weights were computed."""


@dataclass
class RigMeta:
    """Facts about where a rig came from, kept with it (``rig.meta``).

    Attributes
    ----------
    source : Path or None
        The file or folder read; None for a rig built in code. (``rig.path``, where the
        editor's Save goes, starts as this and may change: a recovered document's path is
        its original folder, its source the snapshot.)
    format : str or None
        The registry name of the format read (``"folder"``, ``"gltf"``, ``"bvh"``).
    units : str or None
        The unit of the file's lengths where the format has none (BVH: ``"centimetres"``).
    scale : float or None
        Metres per file unit applied on reading (BVH), None where the format states it.
    scale_guessed : bool
        True when ``scale`` was guessed from the figure's size rather than given.
    rotation_orders : dict[str, str]
        Joint name -> rotation channel order of the source (``"ZXY"``), so that a BVH written
        back keeps each joint's order.
    clip_files : dict[str, Path]
        Clip name -> resolved path of the file the clip was read from (rig folders): a save
        over that folder replaces exactly these (:mod:`rigedit.io.clip_files`).
    notes : dict[str, str]
        What a reader (or the auto-rigger) decided where its format was silent, one line per
        topic (``units``, ``frames``, ``carrier``, ``rotation_order``, ``autorig``), shown by
        ``rigedit info`` and the editor's status bar.
    autorig_report : object or None
        What :func:`rigedit.autorig` decided and measured
        (:class:`rigedit.rigging.autorig.pipeline.AutorigReport`); None for a rig read from a
        file.
    """

    source: Optional[Path] = None
    format: Optional[str] = None
    units: Optional[str] = None
    scale: Optional[float] = None
    scale_guessed: bool = False
    rotation_orders: dict = field(default_factory=dict)
    clip_files: dict = field(default_factory=dict)
    notes: dict = field(default_factory=dict)
    autorig_report: Any = None


@dataclass
class RigData:
    """A rig as plain data: what a file holds, before any rig is built.

    Attributes
    ----------
    skeleton : rigedit.model.skeleton.Skeleton
    vertices : (V, 3) float64
        Rest (bind-pose) positions, model space; (0, 3) for a skeleton without a mesh.
    faces : (F, 3) int64
    indices, weights : (V, K) int and float arrays, or None
        Skin influences; None when the file has none (``Rig.from_data`` computes them).
    clips : dict[str, rigedit.animation.clip.Clip]
    surface : rigedit.surface.Surface or None
        Normals, texture coordinates and materials where the file had them (glTF).
    name : str
    up : {"y", "z"}
        The vertical axis.
    meta : RigMeta
    morphs : rigedit.model.morph.MorphTargets or None
        Morph targets (glTF morph targets, FBX blend shapes) of ``vertices``, in the same
        vertex order; None when the file has none.
    """

    skeleton: Any
    vertices: np.ndarray
    faces: np.ndarray
    indices: Optional[np.ndarray] = None
    weights: Optional[np.ndarray] = None
    clips: dict = field(default_factory=dict)
    surface: Any = None
    name: str = "rig"
    up: str = "y"
    meta: RigMeta = field(default_factory=RigMeta)
    morphs: Optional[MorphTargets] = None

    def __post_init__(self):
        self.vertices = np.asarray(self.vertices, dtype=np.float64)
        self.faces = np.asarray(self.faces, dtype=np.int64)


def as_rig_data(rig):
    """``rig`` as a :class:`RigData`: itself when it is one, else ``rig.data()`` (a
    :class:`rigedit.rig.Rig`, which io does not import)."""
    return rig if isinstance(rig, RigData) else rig.data()


# The Rig-returning readers of old (``rigedit.io.load.load_rig``, ``load_bvh``, ``load_gltf``,
# ``load_rig_folder``) must keep returning a Rig while io imports nothing above it: the rig
# layer hands io its builder when it is imported (rigedit/rig.py, imported by the package
# root, so before any io module can run).
_RIG_BUILDER: Optional[Callable] = None


def register_rig_builder(build):
    """Set the function that makes a rig of a :class:`RigData` (``Rig.from_data``)."""
    global _RIG_BUILDER
    _RIG_BUILDER = build


def build_rig(data, weights_method=None):
    """The :class:`rigedit.rig.Rig` of ``data`` (``Rig.from_data``); for the compatibility
    readers only: new code calls ``Rig.from_data`` itself."""
    if _RIG_BUILDER is None:   # only when rigedit/rig.py was never imported
        raise RuntimeError("rigedit.rig registers the rig builder; import rigedit first")
    return _RIG_BUILDER(data, weights_method=weights_method)
