"""Joints that do not deform the skin, told from a skeleton's structure and names.

Rigs carry joints that no artist paints weight onto: end markers (``HeadTop_End``, ``Toe_End``,
``*_Nub``, Mixamo's fourth finger joint: where the last bone ends), IK and pole targets
(``PoleTarget.L``, ``*_IK_target``), twist and share bones (``CC_Base_L_UpperarmTwist01``,
``CC_Base_L_RibsShareBone``: driven helpers beside a limb bone, at its head or along it) and
carrier roots (a root that only moves the figure: ``root``, ``Armature``, Bandai's
``joint_Root``). Automatic weights that let them take weight steal skin from the bones that
really move it: a leaf end marker gets a tail and a region of its own, a pole target in front
of the knee takes the knee's skin, a carrier root at the ground owns segments through the feet.

:func:`helper_joints` returns a reason for each joint it flags. It needs no mesh; the only
judgement that does (is a root-at-the-ground's bone outside the body?) is left to
:func:`rigedit.binding.tails.deforming_joints`, which takes :func:`carrier_candidates` from here.
Pure numpy; nothing here imports the rest of rigedit.
"""
from __future__ import annotations

import re

import numpy as np

__all__ = ["helper_joints", "carrier_candidates", "END", "TARGET", "TWIST", "SHARE", "CARRIER"]

END = "end marker"
TARGET = "IK or pole target"
TWIST = "twist bone"
SHARE = "share bone"
CARRIER = "carrier root"

# Words are matched on the name split at case changes, digits and separators, so "Toe_End",
# "toeEnd", "HeadTop_End" and "Bip01 R Finger0Nub" all give "end"/"nub", but "Legend" or
# "Bending" do not.
_END_WORDS = {"end", "nub", "endsite"}
_TARGET_WORDS = {"pole", "ik", "ikh", "target", "tgt", "ctrl", "control", "ikpole", "locator"}
_TWIST_WORDS = {"twist", "roll"}
_SHARE_WORDS = {"share", "sharebone"}
_CARRIER_NAMES = {"root", "armature", "master", "world", "ground", "trajectory", "reference",
                  "rootnode", "motion", "carrier"}
# Mixamo's fingers: joints 1-3 deform, 4 is the fingertip marker.
_MIXAMO_TIP = re.compile(r"(thumb|index|middle|ring|pinky)4$", re.IGNORECASE)
_PREFIX = re.compile(r"^(mixamorig\d*|cc_base|bip\d*|def|mch|org|skeleton|armature)[:_|. ]",
                     re.IGNORECASE)


def _words(name):
    """Lower-case words of a joint name (case changes, digits and separators split it)."""
    name = _PREFIX.sub("", name)
    parts = re.split(r"[^A-Za-z]+|(?<=[a-z])(?=[A-Z])", name)
    return [p.lower() for p in parts if p]


def helper_joints(names, parents, heads):
    """Why each joint should not deform, or ``""`` for a joint that may.

    Parameters
    ----------
    names : sequence of str, length J
    parents : (J,) int
        Parent index, -1 for a root; parents come before children.
    heads : (J, 3) float64
        Model-space joint positions at bind time.

    Returns
    -------
    reasons : (J,) object array of str
        :data:`END`, :data:`TARGET`, :data:`TWIST`, :data:`SHARE`, :data:`CARRIER` or ``""``.
        Only leaves (or joints whose descendants are all helpers) are flagged as end
        markers, twist and share bones: a helper in the middle of a chain carries the bone
        below it. A carrier root here is a *candidate* (:func:`carrier_candidates`): named
        like one, or sitting at the model origin or at the edge of the figure.
    """
    parents = np.asarray(parents)
    heads = np.asarray(heads, dtype=np.float64)
    n = len(parents)
    children = [[] for _ in range(n)]
    for j, p in enumerate(parents):
        if p >= 0:
            children[p].append(j)
    reasons = np.full(n, "", dtype=object)
    for j in range(n - 1, -1, -1):  # children first: a helper's helpers are known
        words = set(_words(names[j]))
        leafish = all(reasons[k] for k in children[j])
        if words & _TARGET_WORDS and leafish:
            reasons[j] = TARGET
        elif leafish and (words & _END_WORDS or _MIXAMO_TIP.search(names[j])
                          or names[j].lower().endswith(("_end", ".end", "end_site"))):
            reasons[j] = END if not children[j] or parents[j] >= 0 else ""
        elif leafish and words & _TWIST_WORDS and parents[j] >= 0:
            reasons[j] = TWIST
        elif leafish and words & _SHARE_WORDS and parents[j] >= 0:
            reasons[j] = SHARE
    for j in carrier_candidates(names, parents, heads):
        reasons[j] = CARRIER
    return reasons


def carrier_candidates(names, parents, heads):
    """Roots that may only carry the figure: (R,) int joint indices.

    A root with children qualifies when it is named like a carrier (``root``, ``Armature``,
    ``joint_Root``...), or when it sits at the model origin or on the edge of the box of its
    descendants (no further in than 2% of the box along some axis: on the ground under the
    feet, not inside the body as a hip root is). Whether it really is one needs the mesh
    (its bones outside the body); see :func:`rigedit.binding.tails.deforming_joints`.
    """
    parents = np.asarray(parents)
    heads = np.asarray(heads, dtype=np.float64)
    out = []
    for r in np.flatnonzero(parents < 0):
        desc = _descendants(parents, r)
        if not desc:
            continue
        words = _words(names[r])
        named = bool(words) and (words[-1] in _CARRIER_NAMES
                                 or "".join(words) in _CARRIER_NAMES)
        pts = heads[desc]
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        ext = np.maximum(hi - lo, 1e-12)
        size = float(np.linalg.norm(hi - lo))
        at_origin = np.linalg.norm(heads[r]) <= 1e-3 * max(size, 1e-12)
        edge = np.any(((heads[r] <= lo + 0.02 * ext) | (heads[r] >= hi - 0.02 * ext))
                      & (ext > 0.05 * size))
        if named or at_origin or edge:
            out.append(int(r))
    return np.array(out, dtype=np.int64)


def _descendants(parents, root):
    inside = np.zeros(len(parents), bool)
    inside[root] = True
    for j in range(root + 1, len(parents)):  # parents come before children
        if parents[j] >= 0 and inside[parents[j]]:
            inside[j] = True
    inside[root] = False
    return list(np.flatnonzero(inside))
