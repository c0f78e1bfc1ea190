"""Templates that stretch: the bundled characters' meshes deformed to other proportions (a big
head, short or long arms, arms close to the body, a thick body; a pug's short legs, a llama's
long neck) from a known skeleton, and the shared characters with artist skeletons, embedded
with the bundled templates and measured by CD-J2J (RigNet's metric, % of the bounding-box
diagonal; fingers and end markers left out of the truth).

Each variant is the bundled mesh skinned in a pose that changes the skeleton's proportions
(joint offsets stretched, joint scales), so the truth is the pose's joints. Limits are about
1.3 times what was measured on this machine after the change (noted beside each, with the
figure before it).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import rigedit
from rigedit.embedding import cd_j2j, embed_skeleton

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"

ARM = ("ForeArm", "Hand")
#: Humanoid variants: (offset factors by joint, scales by joint, Euler degrees by joint).
HUMAN = {
    "big head": ({}, {"Head": 1.7}, {}),
    "short arms": ({f"{s}{j}": 0.6 for s in ("Left", "Right") for j in ARM}, {}, {}),
    "long arms": ({f"{s}{j}": 1.35 for s in ("Left", "Right") for j in ARM}, {}, {}),
    "arms close to the body": ({}, {}, {"LeftArm": [0, 0, -68], "RightArm": [0, 0, 68]}),
    "thick body": ({"LeftArm": 1.45, "RightArm": 1.45, "LeftUpLeg": 1.3, "RightUpLeg": 1.3},
                   {"Spine": (1.5, 1.0, 1.5), "Hips": (1.3, 1.0, 1.3),
                    "LeftShoulder": (1 / 1.5, 1.0, 1 / 1.5),
                    "RightShoulder": (1 / 1.5, 1.0, 1 / 1.5), "Neck": (1 / 1.5, 1.0, 1 / 1.5),
                    "LeftUpLeg": (1 / 1.3, 1.0, 1 / 1.3), "RightUpLeg": (1 / 1.3, 1.0, 1 / 1.3)},
                   {}),
}
LEGS = [f"{k}_{s}" for s in "LR" for k in ("fore_lower", "fore_cannon", "fore_hoof",
                                            "hind_shin", "hind_cannon", "hind_hoof")]
#: Quadruped variants, as HUMAN.
QUAD = {
    "short legs (a pug)": ({j: 0.5 for j in LEGS}, {}, {}),
    "long neck (a llama)": ({"neck_2": 2.0, "neck_3": 2.0, "head": 2.0}, {}, {}),
}


def stretched(rig, offsets=None, scales=None, angles=None):
    """The rig's mesh skinned with stretched joint offsets, joint scales and turns.

    Parameters
    ----------
    rig : Rig
    offsets : dict[str, float]
        A joint's rest offset from its parent times this (its bone longer or shorter; the
        skin between follows the blended weights).
    scales : dict[str, float or (3,)]
        A joint's local scale (its part of the mesh, and everything below, bigger).
    angles : dict[str, (3,)]
        Euler degrees of a joint.

    Returns
    -------
    vertices : (V, 3) float64
        Standing on the rig's floor again.
    joints : (J, 3) float64
        The truth: every joint of the pose, shifted with the mesh.
    """
    pose = rig.rest_pose()
    for joint, k in (offsets or {}).items():
        j = rig.skeleton.index[joint]
        pose.translation[j] = rig.skeleton.rest_translation[j] * k
    for joint, s in (scales or {}).items():
        pose.set_scale(joint, np.broadcast_to(np.asarray(s, dtype=float), (3,)))
    for joint, euler in (angles or {}).items():
        pose.set_euler(joint, euler, degrees=True)
    vertices = np.array(rig.skin(pose))
    joints = rig.joint_matrices(pose)[:, :3, 3].copy()
    drop = vertices[:, 1].min() - rig.vertices[:, 1].min()
    vertices[:, 1] -= drop
    joints[:, 1] -= drop
    return vertices, joints


def truth_joints(rig):
    """Template joint indices measured on a bundled character's variants: every deforming
    joint but the ground-level root and the leaf tips the truth leaves out (toes' ends,
    ears, antler tips are kept: they are joints of the skeleton, not end markers)."""
    sk = rig.skeleton
    return [j for j in range(len(sk)) if sk.parents[j] >= 0]


def measure(rig, vertices, joints, **kw):
    """CD-J2J (%) of ``rig``'s template embedded in ``vertices`` against ``joints``."""
    emb = embed_skeleton(vertices, rig.faces, rig.skeleton,
                         template_mesh=(rig.vertices, rig.faces), **kw)
    pick = truth_joints(rig)
    return cd_j2j(emb.positions[pick], joints[pick],
                  float(np.linalg.norm(np.ptp(vertices, axis=0)))), emb


# --------------------------------------------------------------- shared, artist skeletons
_LEG_NAMES = ("UpLeg", "Leg", "Foot", "ToeBase")
#: The bundled humanoid's joints -> a Mixamo character's (same names, ``mixamorig:``
#: prefix); fingers, eyes and the ``_End`` markers are left out.
MIXAMO = {n: f"mixamorig:{n}" for n in
          ["Hips", "Spine", "Spine1", "Spine2", "Neck", "Head"]
          + [f"{s}{k}" for s in ("Left", "Right")
             for k in ("Shoulder", "Arm", "ForeArm", "Hand") + _LEG_NAMES]}
#: The bundled quadruped's joints -> the Quaternius horse's (by anatomy; its IK foot
#: targets stand at the hooves; the belly root ``Body`` and the hind ``BackLeg`` helpers
#: have no counterpart and are left out).
HORSE = {"pelvis": "Back", "spine_1": "Hips", "spine_2": "Torso", "spine_3": "Shoulders",
         "neck_2": "Neck", "head": "Head", "tail_1": "Tail1", "tail_2": "Tail2",
         "tail_3": "Tail3", "tail_4": "Tail4"}
for _s, _t in (("L", "L"), ("R", "R")):
    HORSE.update({f"scapula_{_s}": f"FrontLeg.{_t}", f"fore_upper_{_s}": f"FrontUpLeg.{_t}",
                  f"fore_cannon_{_s}": f"FrontLowLeg.{_t}", f"fore_hoof_{_s}": f"FrontFoot.{_t}",
                  f"hind_thigh_{_s}": f"BackUpLeg.{_t}", f"hind_cannon_{_s}": f"BackLowLeg.{_t}",
                  f"hind_hoof_{_s}": f"BackFoot.{_t}"})
from test_embedding import KHRONOS  # noqa: E402  (CesiumMan's and RiggedFigure's tables)

#: file under ../shared/data -> (bundled template, template joint -> artist joint)
SHARED = {"khronos-gltf/CesiumMan.glb": ("humanoid", KHRONOS["CesiumMan.glb"]),
          "khronos-gltf/RiggedFigure.glb": ("humanoid", KHRONOS["RiggedFigure.glb"]),
          "threejs-characters/Xbot.glb": ("humanoid", MIXAMO),
          "quaternius-farm-animals/Horse.gltf": ("quadruped", HORSE)}


def shared_case(path, template):
    """(vertices, faces, predicted indices, true joints) of a shared character at rest (they
    stand +Y up facing +Z, left at +X, rigedit's frame)."""
    rig = rigedit.load_rig(str(DATA / path))
    _, table = SHARED[path]
    rest = rig.rest_pose()
    joints = rig.joint_matrices(rest)[:, :3, 3]
    pick = [template.skeleton.index[k] for k in table]
    truth = joints[[rig.skeleton.index[v] for v in table.values()]]
    return np.array(rig.skin(rest)), rig.faces, pick, truth
