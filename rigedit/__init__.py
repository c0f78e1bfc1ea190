"""rigedit: a rig editor for 3D characters (skeleton, skinning, posing, clips).

>>> import rigedit
>>> rig = rigedit.load_rig()            # the bundled quadruped
>>> pose = rig.rest_pose()
>>> pose.set_euler("neck_1", [0, 0, 20], degrees=True)
>>> verts = rig.skin(pose)
"""
from __future__ import annotations

import importlib.resources
import os
from pathlib import Path

from .animation import Clip, Track
from .errors import RigFileError
from .model import Pose, Skeleton, SkinBinding
from .rig import Rig

__all__ = ["load_rig", "save_rig", "retarget", "autorig", "resolve_rig_path", "BUNDLED",
           "ASSETS_DIR", "Rig", "Skeleton", "Pose", "Clip", "Track", "SkinBinding", "RigFileError"]
__version__ = "0.1.0"


def _assets_dir():
    """The folder of the bundled characters: ``$RIGEDIT_ASSETS`` when set, else the data package
    ``rigedit.assets`` through ``importlib.resources`` (the repository's top-level ``assets/``
    folder: copied into the package by a normal install, mapped onto ``assets/`` by an editable
    one), else the ``assets/`` folder beside this package in a plain checkout."""
    if os.environ.get("RIGEDIT_ASSETS"):
        return Path(os.environ["RIGEDIT_ASSETS"])
    try:
        location = Path(str(importlib.resources.files(f"{__name__}.assets")))
    except ImportError:  # a checkout on sys.path without an install of the package
        location = None
    if location is not None and (location / BUNDLED[0]).is_dir():
        return location
    return Path(__file__).resolve().parent.parent / "assets"


#: Names accepted wherever a rig is asked for; the first is the default.
BUNDLED = ("quadruped", "humanoid")
#: Where the bundled characters live (see ``_assets_dir``).
ASSETS_DIR = _assets_dir()


def resolve_rig_path(rig=None):
    """Path of a rig folder from a bundled name, a path, or None (the default character)."""
    if rig is None:
        rig = BUNDLED[0]
    if str(rig) in BUNDLED and not Path(rig).exists():
        return ASSETS_DIR / str(rig)
    return Path(rig)


def load_rig(rig=None, weights_method=None, scale=None):
    """Load a rig: a bundled name (``quadruped``, the default, or ``humanoid``), a rig folder,
    a ``.glb``/``.gltf`` file or a ``.bvh`` file (see :func:`rigedit.io.load.load_rig`).

    Raises
    ------
    RigFileError
        When a file is missing or malformed; the message names the file.
    """
    from .io.load import load_rig as _load_rig

    return _load_rig(rig, weights_method=weights_method, scale=scale)


def retarget(source_rig, source_clip, target_rig, map=None, name=None, clean_feet=True):
    """Retarget a clip onto another character: two humanoids, or any two skeletons with legs
    whose joints share names or are mapped (see :func:`rigedit.rigging.retarget.pipeline`)."""
    from .rigging.retarget.pipeline import retarget as _retarget

    return _retarget(source_rig, source_clip, target_rig, map=map, name=name,
                     clean_feet=clean_feet)


def autorig(mesh, template="humanoid", up=None, forward=None, weights="heat", clips=True,
            progress=None, hints=None):
    """Rig a static mesh: embed a template skeleton, bind it, give it the template's clips
    (see :func:`rigedit.rigging.autorig.pipeline.autorig`; ``hints`` pins joints, {name: (x, y, z)}
    in the mesh's coordinates); ``rig.autorig_report`` says what was decided (orientation,
    checks, stage times)."""
    from .rigging.autorig.pipeline import autorig as _autorig

    return _autorig(mesh, template=template, up=up, forward=forward, weights=weights,
                    clips=clips, progress=progress, hints=hints)


def save_rig(rig, path, clips=None):
    """Save a rig; the format follows the path (a folder, .glb, .gltf, .bvh). See
    :func:`rigedit.io.save.save_rig`."""
    from .io.save import save_rig as _save_rig

    return _save_rig(rig, path, clips=clips)
