"""Joint names read as a rigger reads them: a side and a base word; joints and fingers
paired by name.

Sides come from the names (``L``/``R``/``Left``/``Right``, ``.L``, ``_l``, CMU's ``lhand``),
after prefixes such as ``mixamorig:`` and ``CC_Base_`` and filler words (``joint``,
``bone``...) are dropped (:func:`normalise_name`). Two skeletons' joints pair by equal names,
then equal normalised names (:func:`name_pairs`); fingers pair by finger and number when
both hands have them (:func:`finger_pairs`).
"""
from __future__ import annotations

import re

__all__ = ["normalise_name", "name_pairs", "finger_pairs", "FINGERS", "KNEE", "ELBOW"]

_NOISE = {"joint", "jnt", "bone", "skeleton", "def", "bip01", "bip001", "mixamorig", "end", "j",
          "b", "bn", "mch", "org"}
_SIDES = {"l": "L", "left": "L", "r": "R", "right": "R"}
#: Base words of a knee joint and of an elbow joint (:func:`.slots.bend_index` takes the
#: one joint of a chain named so).
KNEE = {"leg", "lowerleg", "lowleg", "knee", "shin", "calf", "crus"}
ELBOW = {"forearm", "lowerarm", "elbow"}
#: Prefixes a rig puts on every joint (Character Creator / iClone's ``CC_Base_``, 3ds Max
#: biped's ``Bip01 ``), dropped before the name is read.
_PREFIX = re.compile(r"^(CC_Base_|RL_|Bip0*1[ _]|Bip001[ _])", re.IGNORECASE)
_BODY_WORDS = ("hand", "foot", "fingers", "finger", "thumb", "hip", "hipjoint", "toe", "arm",
               "leg", "shoulder", "collar", "upleg", "foreArm")


def normalise_name(name):
    """Split a joint name into a side and a base word.

    Parameters
    ----------
    name : str

    Returns
    -------
    side : {"L", "R", None}
    base : str
        Lower case, without namespace (``mixamorig1:``), separators, digits and filler words
        (``joint``, ``bone``, ``skeleton``...).

    Examples
    --------
    >>> normalise_name("mixamorig:LeftForeArm")
    ('L', 'forearm')
    >>> normalise_name("leg_joint_R_2")
    ('R', 'leg')
    """
    name = _PREFIX.sub("", name.split(":")[-1].split("|")[-1])
    tokens = []
    for part in re.split(r"[\s_.\-]+", name):
        # camelCase and a capital side letter glued to a word: "LHipJoint" -> L, Hip, Joint
        tokens += re.findall(r"[A-Z]+(?=[A-Z][a-z])|[A-Z]?[a-z]+|[A-Z]+|\d+", part)
    side, words = None, []
    for tok in tokens:
        low = tok.lower()
        if low in _SIDES and side is None:
            side = _SIDES[low]
        elif low.isdigit() or low in _NOISE:
            continue
        elif side is None and low[0] in "lr" and low[1:] in {w.lower() for w in _BODY_WORDS}:
            side, words = _SIDES[low[0]], words + [low[1:]]  # CMU's "lhand", "rhand"
        else:
            words.append(low)
    return side, "".join(words)


#: Finger names, in the order they are looked for in a joint's base word ("mid" after
#: "middle"; Mixamo's "handindex", iClone's "index", Blender's "f_index").
FINGERS = (("thumb", ("thumb",)), ("index", ("index", "pointer")),
           ("middle", ("middle", "mid")), ("ring", ("ring",)),
           ("pinky", ("pinky", "little", "small")))


def _finger_runs(skeleton, hand):
    """Each finger below ``hand``: {finger: [joints from its base out]} for the children
    runs whose names say which finger (down the child with the most joints below it)."""
    out = {}
    for c in skeleton.children(hand):
        run = [int(c)]
        while len(skeleton.children(run[-1])):
            kids = skeleton.children(run[-1])
            run.append(int(max(kids, key=lambda k: len(skeleton.subtree(k)))))
        words = " ".join(normalise_name(skeleton.names[j])[1] for j in run)
        for finger, keys in FINGERS:
            if any(k in words for k in keys):
                # named twice (a palm joint and its finger both "middle"): the longer run
                if finger not in out or len(run) > len(out[finger]):
                    out[finger] = run
                break
    return out


def finger_pairs(src_skeleton, src_hand, tgt_skeleton, tgt_hand):
    """The finger joints of two hands paired: the same finger (by name: thumb, index,
    middle, ring, pinky) on both, joint by joint from the hand out, by the numbers in their
    names where both have them (Mixamo's ``Index1..4`` and iClone's ``Index1..3`` pair 1-3
    and leave Mixamo's tip), else in order.

    Returns
    -------
    pairs : list of (int, int)
        Source joint, target joint; empty when either hand has no named fingers.
    """
    def number(sk, j):
        digits = re.findall(r"\d+", sk.names[j].split(":")[-1])
        return int(digits[-1]) if digits else None

    s_runs, t_runs = _finger_runs(src_skeleton, src_hand), _finger_runs(tgt_skeleton, tgt_hand)
    pairs = []
    for finger in [f for f, _ in FINGERS if f in s_runs and f in t_runs]:  # in a fixed order
        a, b = s_runs[finger], t_runs[finger]
        na = [number(src_skeleton, j) for j in a]
        nb = [number(tgt_skeleton, j) for j in b]
        if None not in na + nb and len(set(na)) == len(na) and len(set(nb)) == len(nb):
            pairs += [(a[na.index(k)], b[nb.index(k)]) for k in sorted(set(na) & set(nb))]
        else:
            pairs += list(zip(a, b))
    return pairs


def name_pairs(src_skeleton, tgt_skeleton, taken=None):
    """Joints paired by name: equal names first, then equal normalised names (side and base
    word, :func:`normalise_name`) with their numbers (``spine_2`` and ``Spine2``), then
    without them, each where exactly one joint on each side has it.

    Parameters
    ----------
    src_skeleton, tgt_skeleton : Skeleton
    taken : dict[str, str], optional
        Pairs already made (source -> target); their joints are left out.

    Returns
    -------
    mapping : dict[str, str]
        The new pairs, source joint name -> target joint name.
    """
    taken = dict(taken or {})
    s_used, t_used = set(taken), set(taken.values())
    out = {}
    for nm in src_skeleton.names:
        if nm not in s_used and nm in tgt_skeleton.index and nm not in t_used:
            out[nm] = nm
    s_used |= set(out)
    t_used |= set(out.values())

    def numbers(nm):
        return tuple(int(d) for d in re.findall(r"\d+", nm.split(":")[-1].split("|")[-1]))

    def keyed(names, used, key):
        keys = {}
        for nm in names:
            if nm not in used:
                keys.setdefault(key(nm), []).append(nm)
        return keys

    for key in (lambda nm: normalise_name(nm) + numbers(nm), normalise_name):
        s_keys = keyed(src_skeleton.names, s_used, key)
        for k, cand in keyed(tgt_skeleton.names, t_used, key).items():
            if k[1] and len(cand) == 1 and len(s_keys.get(k, [])) == 1:
                out[s_keys[k][0]] = cand[0]
                s_used.add(s_keys[k][0])
                t_used.add(cand[0])
    return out
