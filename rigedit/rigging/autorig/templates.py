"""Auto-rig templates: reading one, and the standing poses of it to embed.

Used by :mod:`.autorig`.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ...errors import RigFileError

__all__ = ["load_template", "template_poses", "upright", "rest_model"]


def rest_model(skeleton):
    """(J, 4, 4) model matrices of the skeleton's rest pose."""
    return skeleton.forward(skeleton.rest_local_matrices())


def load_template(template):
    """The template's rig (for its clips; None for a bare skeleton), skeleton and a name.

    Parameters
    ----------
    template : str, Path, Rig or Skeleton
        ``"humanoid"``, ``"quadruped"``, a skeleton JSON file, a rig folder, a ``.glb``/
        ``.gltf`` or ``.bvh`` file, or a rig or skeleton object.

    Raises
    ------
    RigFileError
        A file that is not a skeleton, or a skeleton without limbs (fewer than 3 joints).
    """
    from ...model.skeleton import Skeleton
    from ...rig import Rig

    if isinstance(template, Rig):
        rig, skeleton, name = template, template.skeleton, template.name
    elif isinstance(template, Skeleton):
        rig, skeleton, name = None, template, "skeleton"
    else:
        from ...io.bundled import BUNDLED
        from ...io.load import read_rig
        from ...io.mesh import MESH_SUFFIXES

        path = Path(template)
        name = str(template)
        suffix = path.suffix.lower()
        if suffix in MESH_SUFFIXES:
            raise RigFileError(path, f"expected a template skeleton (humanoid, quadruped, a "
                                     f"skeleton .json, a rig folder, .glb or .bvh), got a "
                                     f"{suffix} mesh")
        if suffix == ".json":
            from ...io.frames import axis_change, change_axes
            from ...io.skeleton_json import load_skeleton

            skeleton, meta = load_skeleton(path)
            if meta["up"] != "y":
                skeleton, _ = change_axes(skeleton, {}, axis_change(meta["up"], "y"))
            rig = None
        elif str(template) in BUNDLED or path.exists() or suffix in (".glb", ".gltf", ".bvh"):
            rig = Rig.from_data(read_rig(template))
            skeleton = rig.skeleton
        else:
            raise RigFileError(path, "expected a template: humanoid, quadruped, a skeleton "
                                     "file, a rig folder, .glb or .bvh; got nothing there")
    if len(skeleton) < 3:
        raise RigFileError(name, f"expected a template skeleton with a body and limbs, got "
                                 f"{len(skeleton)} joint{'s' * (len(skeleton) != 1)}")
    return rig, skeleton, name


def template_poses(skeleton, rig, what):
    """Standing poses of the template to embed, facing +Z, best first: ``[(skeleton, pose)]``.

    The rest pose only, for a template with a mesh or without clips. A motion-only template
    (a BVH) may have a rest that does not stand as its mesh-less figure would: lying along
    one axis (Bandai's) or with splayed legs (CMU's). Then the rest, when it stands (the
    retargeting's calibration finds humanoid limbs, else legs on the floor), and the first
    frame of its first clip that stands, turned about +Y to face +Z, are offered in turn;
    :func:`autorig` embeds the first that fits. The clips are retargeted from the template's
    own rest all the same.
    """
    from ...model.skeleton import Skeleton
    from ..retarget.calibrate import Calibration
    from ..retarget.limbs import LegCalibration

    if rig is None or len(rig.vertices) or not rig.clips:
        return [(skeleton, "rest")]
    poses = [("rest", rest_model(skeleton))]
    for name in sorted(rig.clips):
        poses.append((f"frame 0 of {name}",
                      skeleton.forward(rig.clips[name].sample(0.0).local_matrices())))
    out = []
    for source, mats in poses:
        for kind in (Calibration, LegCalibration):
            try:
                cal = kind(skeleton, mats, source, what)
                break
            except ValueError:
                cal = None
        if cal is None:
            continue
        if source == "rest":
            out.append((skeleton, source))
        else:
            fwd = np.asarray(cal.forward, dtype=np.float64)
            heading = Rotation.from_euler("y", np.arctan2(-fwd[0], fwd[2])).as_matrix()
            mats = mats.copy()
            mats[:, :3, :] = heading @ mats[:, :3, :]
            local = mats.copy()
            has = skeleton.parents >= 0
            local[has] = np.linalg.inv(mats[skeleton.parents[has]]) @ mats[has]
            rot = Rotation.from_matrix(local[:, :3, :3]).as_quat()
            out.append((Skeleton(list(skeleton.names), skeleton.parents.copy(),
                                 local[:, :3, 3], rot, deform=skeleton.deform.copy()), source))
        if len(out) == 2:
            break
    return out or [(skeleton, "rest")]


def upright(skeleton):
    """A template stands tall (a biped) when it stands on at most two feet: leaf joints
    within 10% of its height of the lowest joint (a quadruped has four hooves there; its
    height says nothing, antlers make the elk taller than long)."""
    pos = rest_model(skeleton)[:, :3, 3]
    leaves = np.setdiff1d(np.arange(len(skeleton)), skeleton.parents)
    low = pos[leaves, 1] <= pos[:, 1].min() + 0.1 * max(np.ptp(pos[:, 1]), 1e-12)
    return bool(low.sum() <= 2)
