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

from testpaths import REPO
import re
from pathlib import Path

import numpy as np
import pytest

import rigedit
from rigedit.embedding import cd_j2j, embed_skeleton

DATA = REPO.parent / "shared" / "data"

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
    "long tail (a horse's)": ({"tail_2": 1.6, "tail_3": 1.6, "tail_4": 1.6}, {"tail_1": 2.5}, {}),
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


#: Joints RigNet's CD-J2J leaves out of the truth, as the issue measures it: fingers and end
#: markers (``HeadTop_End``, ``LeftToe_End``).
LEFT_OUT = re.compile(r"thumb|index|middle|ring|pinky|finger|_end$", re.IGNORECASE)


def full_truth(path):
    """Every artist joint of a shared character at rest but fingers and end markers (the
    truth of the issue's CD-J2J, against every template joint: no name table)."""
    rig = rigedit.load_rig(str(DATA / path))
    joints = rig.joint_matrices(rig.rest_pose())[:, :3, 3]
    keep = [j for j, n in enumerate(rig.skeleton.names) if not LEFT_OUT.search(n)]
    return joints[keep]


def shared_case(path, template):
    """(vertices, faces, predicted indices, true joints) of a shared character at rest (they
    stand +Y up facing +Z, left at +X, rigedit's frame). The mesh is what ``rigedit.autorig``
    embeds: the body, or the watertight proxy of an open or many-part one (Xbot is open at
    the eyes, with its joints' rings as separate parts)."""
    from rigedit.rigging.autorig.mesh_check import check_mesh

    rig = rigedit.load_rig(str(DATA / path))
    _, table = SHARED[path]
    rest = rig.rest_pose()
    joints = rig.joint_matrices(rest)[:, :3, 3]
    pick = [template.skeleton.index[k] for k in table]
    truth = joints[[rig.skeleton.index[v] for v in table.values()]]
    vertices, faces = check_mesh(np.array(rig.skin(rest)), rig.faces, path).embedding_mesh()
    used = np.unique(faces)
    remap = np.full(len(vertices), -1)
    remap[used] = np.arange(len(used))
    return vertices[used], remap[faces], pick, truth


# ------------------------------------------------------------------------------ tests
#: (variant, limit %): measured after the change, before it in the note (bench_embedding).
LIMITS = {"big head": 1.0,                    # 0.73 (0.73)
          "short arms": 1.6,                  # 1.19 (1.19)
          "long arms": 1.4,                   # 1.05 (1.05)
          "arms close to the body": 1.8,      # 1.38 (1.38)
          "thick body": 2.4,                  # 1.87 (1.87)
          "short legs (a pug)": 3.1,          # 2.36 (2.49)
          "long neck (a llama)": 2.4,         # 1.84 (1.85)
          "long tail (a horse's)": 0.8}       # 0.58 (1.09: the tail carried at its length)


@pytest.mark.parametrize("label", list(LIMITS))
def test_stretched_bundled_characters(label, humanoid, quadruped):
    rig, spec = (humanoid, HUMAN[label]) if label in HUMAN else (quadruped, QUAD[label])
    vertices, joints = stretched(rig, *spec)
    cd, _ = measure(rig, vertices, joints)
    assert cd < LIMITS[label]


def test_a_long_tail_is_embedded_to_its_end(quadruped):
    """A tail four times the template's (and thicker): before, carried at the template's
    length, its end sat 18% of the size off; embedded, stretched along its branch, under 2%."""
    vertices, joints = stretched(quadruped, *QUAD["long tail (a horse's)"])
    _, emb = measure(quadruped, vertices, joints)
    diag = float(np.linalg.norm(np.ptp(vertices, axis=0)))
    for name in ("tail_1", "tail_2", "tail_3", "tail_4"):
        j = quadruped.skeleton.index[name]
        assert np.linalg.norm(emb.positions[j] - joints[j]) / diag < 0.02, name  # 0.7-0.9%
    assert "tail_4" in emb.placed


def test_a_tail_is_optional_on_a_mesh_without_one(quadruped):
    """The bundled quadruped's mesh with its tail cut off (the tail's vertices pulled into
    the rump): the tail is carried, not pushed into a leg."""
    sk = quadruped.skeleton
    tail = [sk.index[f"tail_{i}"] for i in range(1, 5)]
    weights = np.zeros(len(quadruped.vertices))
    idx, w = quadruped.binding.indices, quadruped.binding.weights
    for j in tail:
        weights += np.where(idx == j, w, 0.0).sum(axis=1)
    vertices = quadruped.vertices.copy()
    rump = sk.bind_matrices[sk.index["tail_1"], :3, 3]
    cut = weights > 0.5
    vertices[cut] = rump + 0.3 * (vertices[cut] - rump)
    truth = sk.bind_matrices[:, :3, 3]
    emb = embed_skeleton(vertices, quadruped.faces, sk,
                         template_mesh=(quadruped.vertices, quadruped.faces))
    hoofs = [sk.index[n] for n in ("hind_hoof_L", "hind_hoof_R")]
    assert np.all(np.linalg.norm(emb.positions[tail] - truth[sk.index["pelvis"]], axis=1)
                  < 0.5 * np.linalg.norm(truth[hoofs[0]] - truth[sk.index["pelvis"]]))


#: (shared character, limit %): measured after, before in the note.
SHARED_LIMITS = {"khronos-gltf/CesiumMan.glb": 4.0,           # 2.99 (2.99)
                 "khronos-gltf/RiggedFigure.glb": 4.0,        # 3.17 (3.17)
                 "threejs-characters/Xbot.glb": 1.6,          # 1.04 (1.04, volume proxy)
                 "quaternius-farm-animals/Horse.gltf": 5.5}   # 4.22 (4.52)


@pytest.mark.parametrize("path", list(SHARED_LIMITS))
def test_shared_characters_with_artist_skeletons(path, humanoid, quadruped):
    template = humanoid if SHARED[path][0] == "humanoid" else quadruped
    vertices, faces, pick, truth = shared_case(path, template)
    emb = embed_skeleton(vertices, faces, template.skeleton,
                         template_mesh=(template.vertices, template.faces))
    cd = cd_j2j(emb.positions[pick], truth, float(np.linalg.norm(np.ptp(vertices, axis=0))))
    assert cd < SHARED_LIMITS[path]
