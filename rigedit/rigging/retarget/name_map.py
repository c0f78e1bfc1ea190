"""Humanoid joint maps: canonical slots found from the tree's shape and its joint names.

A humanoid's joints are sorted into *slots*: ``hips``, the spine interior, ``chest`` (where the
arms branch), ``neck``, ``head`` and per side ``clavicle``, ``upper_arm``, ``forearm``,
``hand``, ``thigh``, ``shin``, ``foot``, ``toe`` (suffix ``_L`` / ``_R``). Names alone cannot
do it: CMU's ``LeftShoulder`` is an upper arm where Mixamo's is a clavicle, and CesiumMan
numbers its arm joints 4, 3, 2. So the limbs are found by structure, in a pose where the figure
stands (the calibration pose): the hips are the first joint with two chains going down and one
going up, the chest the first joint up the spine with two side chains; in a limb chain the
knee (elbow) is the joint named so when exactly one is, otherwise the joint between the two
longest consecutive segments. Sides come from the names (``L``/``R``/``Left``/``Right``,
``.L``, ``_l``, prefixes such as ``mixamorig:`` and ``CC_Base_``) when both chains carry
one, otherwise from the side of the figure's left (``up x forward``, forward from heel to
toe). The legs may hang from a pelvis joint below the hips (iClone), limb chains pass over
twist and share bones beside the real child, and sizes leave out the joints above the first
branch (a carrier root may stand metres away). Fingers pair by name and number when both
hands have them (:func:`finger_pairs`); :func:`unmapped_parts` lists the limbs, spine and
head a map leaves out.
"""
from __future__ import annotations

import json
import re

import numpy as np

from ...errors import RigFileError

__all__ = ["normalise_name", "find_slots", "auto_map", "name_pairs", "load_map", "save_map",
           "bend_index", "interior_map", "finger_pairs", "FINGERS", "LIMB_SLOTS",
           "BODY_PARTS", "unmapped_parts"]

LIMB_SLOTS = ("clavicle", "upper_arm", "forearm", "hand", "thigh", "shin", "foot", "toe")
_NOISE = {"joint", "jnt", "bone", "skeleton", "def", "bip01", "bip001", "mixamorig", "end", "j",
          "b", "bn", "mch", "org"}
_SIDES = {"l": "L", "left": "L", "r": "R", "right": "R"}
_KNEE = {"leg", "lowerleg", "lowleg", "knee", "shin", "calf", "crus"}
_ELBOW = {"forearm", "lowerarm", "elbow"}
_HIPS = {"hips", "hip", "pelvis"}
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


def _subtree_stats(skeleton, points):
    """Per joint: lowest and highest y, and largest distance from the joint, over its subtree.

    points : (J, 3) joint positions; leaf tails are folded in by the caller via ``points``."""
    n = len(skeleton)
    lo, hi = points[:, 1].copy(), points[:, 1].copy()
    for j in range(n - 1, 0, -1):
        p = skeleton.parents[j]
        if p >= 0:
            lo[p], hi[p] = min(lo[p], lo[j]), max(hi[p], hi[j])
    return lo, hi


def _figure_joints(skeleton):
    """Joints from the first branching joint (or the last joint of a chain) down: the ones
    above it only carry the figure."""
    j = int(np.flatnonzero(skeleton.parents < 0)[0])
    while len(skeleton.children(j)) == 1:
        j = int(skeleton.children(j)[0])
    return skeleton.subtree(j)


def _chain(skeleton, start, score):
    """Follow the child with the highest ``score`` from ``start`` down to a leaf."""
    chain = [start]
    while True:
        kids = skeleton.children(chain[-1])
        if len(kids) == 0:
            return chain
        chain.append(int(kids[np.argmax(score[kids])]))


def bend_index(skeleton, chain, points, keywords):
    """Index in ``chain`` of the knee or elbow: the one joint named so, else the joint between
    the two longest consecutive segments (it needs a joint on each side)."""
    named = [i for i, j in enumerate(chain) if normalise_name(skeleton.names[j])[1] in keywords]
    if len(named) == 1 and 1 <= named[0] <= len(chain) - 2:
        return named[0]
    if len(chain) < 3:
        return None
    seg = np.linalg.norm(np.diff(points[chain], axis=0), axis=1)
    return int(np.argmax(seg[:-1] + seg[1:])) + 1


def find_slots(skeleton, points, what="skeleton"):
    """Sort a humanoid skeleton's joints into slots.

    Parameters
    ----------
    skeleton : Skeleton
    points : (J, 3) float64
        Model-space joint positions in a standing pose (Y up).
    what : str
        How to name the skeleton in errors (a file name).

    Returns
    -------
    slots : dict[str, int]
        Slot name -> joint index (``hips``, ``chest``, ``neck``, ``head``, ``thigh_L``...).
    chains : dict[str, list[int]]
        ``spine``: hips to chest inclusive; ``neck``: chest's child up to the head.
    forward : (3,) float64
        The figure's horizontal forward direction (heel to toe), unit length.

    Raises
    ------
    ValueError
        When no hips with two legs below and a spine above, or no arms, are found.
    """
    points = np.asarray(points, dtype=np.float64)
    n = len(skeleton)
    # the figure's size, without the joints above its first branch: a carrier root (Bandai's
    # joint_Root, iClone's RL_BoneRoot) may stand metres from the figure
    size = float(np.ptp(points[_figure_joints(skeleton)], axis=0).max()) or 1.0
    lo, hi = _subtree_stats(skeleton, points)
    count = np.ones(n)
    reach = np.zeros(n)  # furthest distance from each joint within its subtree
    for j in range(n - 1, 0, -1):
        p = skeleton.parents[j]
        if p >= 0:
            count[p] += count[j]
    for j in range(n):
        a = j
        while a >= 0:
            reach[a] = max(reach[a], np.linalg.norm(points[j] - points[a]))
            a = skeleton.parents[a]
    hips = None

    def going_down(j):
        return [c for c in skeleton.children(j)
                if lo[c] < points[j, 1] - 0.25 * size and count[c] >= 2]

    for j in range(n):
        kids = skeleton.children(j)
        down = going_down(j)
        up = [c for c in kids if hi[c] > points[j, 1] + 0.15 * size]
        if len(down) < 2 and up:
            # the legs may hang from a pelvis joint below the hips (iClone's CC_Base_Pelvis:
            # the hips' child with the two legs and nothing going up)
            for c in down:
                if len(going_down(c)) >= 2 and not any(hi[k] > points[j, 1] + 0.15 * size
                                                        for k in skeleton.children(c)):
                    down = going_down(c)
                    break
        if len(down) >= 2 and up:
            hips, legs = j, sorted(down, key=lambda c: lo[c])[:2]
            spine_start = max(up, key=lambda c: hi[c])
            break
    if hips is None:
        raise ValueError(f"{what}: expected a humanoid with two legs (two joint chains going "
                         f"down from the hips) and a spine, found no such joint")
    # down the child with the most joints below it (the foot and toes, not a twist or share
    # helper bone beside them), the lowest on a tie
    leg_chains = [_chain(skeleton, c, count * 4 * size - lo) for c in legs]
    slots = {"hips": hips}
    spine = [hips] + _chain(skeleton, spine_start, hi)
    chest, arms = None, []
    for i, j in enumerate(spine[1:], 1):
        kids = [c for c in skeleton.children(j) if c != (spine[i + 1] if i + 1 < len(spine)
                                                          else -1)]
        side = [c for c in kids if count[c] >= 3 and reach[c] > 0.12 * size]
        if len(side) >= 2:
            chest, arms = j, sorted(side, key=lambda c: -reach[c])[:2]
            cut = i
            break
    if chest is None:
        raise ValueError(f"{what}: expected two arms branching from the spine, found none")
    rise = points[chest] - points[hips]
    if rise[1] < 0.7 * np.linalg.norm(rise):  # more than 45 degrees from vertical
        raise ValueError(f"{what}: expected an upright spine from the hips "
                         f"({skeleton.names[hips]}) to the chest ({skeleton.names[chest]}), "
                         f"got one {np.degrees(np.arccos(rise[1] / np.linalg.norm(rise))):.0f} "
                         f"degrees from vertical (not a standing humanoid)")
    slots["chest"] = chest
    chains = {"spine": spine[:cut + 1], "neck": spine[cut + 1:]}
    neck = chains["neck"]
    if neck:
        heads = [j for j in neck if normalise_name(skeleton.names[j])[1] == "head"]
        head = heads[0] if len(heads) == 1 else neck[-1]
        chains["neck"] = neck[:neck.index(head) + 1]
        slots["head"] = head
        if len(chains["neck"]) >= 2:
            slots["neck"] = chains["neck"][0]
    # Forward: from each ankle to its toe (or the foot's end), horizontal.
    limbs = {}
    fwd = np.zeros(3)
    for ch in leg_chains:
        k = bend_index(skeleton, ch, points, _KNEE)
        if k is None or k + 1 >= len(ch):
            raise ValueError(f"{what}: expected a leg of hip, knee and ankle, got the chain "
                             f"{[skeleton.names[j] for j in ch]}")
        part = {"thigh": ch[k - 1], "shin": ch[k], "foot": ch[k + 1]}
        if k + 2 < len(ch):
            part["toe"] = ch[k + 2]
        end = points[ch[-1]] if ch[-1] != ch[k + 1] else points[ch[k + 1]]
        fwd += (end - points[ch[k + 1]]) * [1, 0, 1]
        limbs[ch[0]] = part
    for c in arms:
        ch = _chain(skeleton, c, reach)
        k = bend_index(skeleton, ch, points, _ELBOW)
        if k is None:
            raise ValueError(f"{what}: expected an arm of shoulder, elbow and wrist, got the "
                             f"chain {[skeleton.names[j] for j in ch]}")
        part = {"upper_arm": ch[k - 1], "forearm": ch[k], "hand": ch[k + 1]}
        if k >= 2:
            part["clavicle"] = ch[k - 2]
        limbs[c] = part
    if np.linalg.norm(fwd) < 1e-6 * size:
        fwd = np.array([0.0, 0.0, 1.0])
    fwd /= np.linalg.norm(fwd)
    left = np.cross([0.0, 1.0, 0.0], fwd)
    for pair in (legs, arms):
        named = [_side_of(skeleton, limbs[c]) for c in pair]
        if sorted(s for s in named if s) != ["L", "R"]:
            x = [float(np.dot(points[c] - points[hips], left)) for c in pair]
            named = ["L", "R"] if x[0] > x[1] else ["R", "L"]
        for c, s in zip(pair, named):
            for slot, j in limbs[c].items():
                slots[f"{slot}_{s}"] = j
    return slots, chains, fwd


def _side_of(skeleton, part):
    """The side the names of a limb's joints agree on, or None."""
    sides = {normalise_name(skeleton.names[j])[0] for j in part.values()} - {None}
    return sides.pop() if len(sides) == 1 else None


def interior_map(src_chain, src_points, tgt_chain, tgt_points):
    """Pair the interior joints of two chains (ends excluded) by nearest fraction of length,
    one to one and in order."""
    def fractions(chain, points):
        seg = np.linalg.norm(np.diff(points[chain], axis=0), axis=1)
        total = seg.sum() or 1.0
        return np.cumsum(seg)[:-1] / total
    s_in, t_in = src_chain[1:-1], tgt_chain[1:-1]
    if not s_in or not t_in:
        return []
    fs, ft = fractions(src_chain, src_points), fractions(tgt_chain, tgt_points)
    pairs, used = [], set()
    for ti in np.argsort(np.abs(ft - 0.5)):  # the middle first: it carries the bend
        free = [si for si in range(len(s_in)) if si not in used]
        if not free:
            break
        si = min(free, key=lambda s: abs(fs[s] - ft[ti]))
        # keep the order: no crossing with pairs already made
        if all((si - a) * (ti - b) > 0 for a, b in pairs):
            pairs.append((si, ti))
            used.add(si)
    return [(s_in[a], t_in[b]) for a, b in sorted(pairs)]


def auto_map(src_skeleton, src_points, tgt_skeleton, tgt_points, src_what="source",
             tgt_what="target"):
    """The joint map between two humanoids: slot to slot, spine and neck interiors by
    fraction of length, then any other joints whose normalised names (with side) agree.

    Parameters
    ----------
    src_skeleton, tgt_skeleton : Skeleton
    src_points, tgt_points : (J, 3) float64
        Joint positions in a standing pose of each.

    Returns
    -------
    mapping : dict[str, str]
        Source joint name -> target joint name.
    """
    s_slots, s_chains, _ = find_slots(src_skeleton, src_points, src_what)
    t_slots, t_chains, _ = find_slots(tgt_skeleton, tgt_points, tgt_what)
    pairs = [(s_slots[k], t_slots[k]) for k in t_slots if k in s_slots]
    for name in ("spine", "neck"):
        pairs += interior_map(s_chains[name], src_points, t_chains[name], tgt_points)
    for side in "LR":
        pairs += finger_pairs(src_skeleton, s_slots[f"hand_{side}"], tgt_skeleton,
                              t_slots[f"hand_{side}"])
    mapping = {src_skeleton.names[a]: tgt_skeleton.names[b] for a, b in pairs}
    mapping.update(name_pairs(src_skeleton, tgt_skeleton, mapping))
    return mapping


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


#: The parts of a humanoid a map must reach, each by the slots that make it.
BODY_PARTS = (("left arm", ("upper_arm_L", "forearm_L", "hand_L")),
              ("right arm", ("upper_arm_R", "forearm_R", "hand_R")),
              ("left leg", ("thigh_L", "shin_L", "foot_L")),
              ("right leg", ("thigh_R", "shin_R", "foot_R")),
              ("spine", ("chest",)), ("head", ("head",)))


def unmapped_parts(calibration, mapped):
    """The parts of the target a joint map leaves (partly) unmapped.

    Parameters
    ----------
    calibration : Calibration, LegCalibration or BareCalibration
        The target's.
    mapped : iterable of int
        The target joints the map reaches.

    Returns
    -------
    parts : list of str
        Humanoids (whatever calibrated the pair): ``"left arm"``, ``"right leg"``,
        ``"spine"``, ``"head"``, each with the joints missing; other skeletons: each leg
        none of whose joints is mapped (by its foot) and the spine (hips to chest). Empty
        when everything is reached.
    """
    mapped = set(mapped)
    sk = calibration.skeleton
    out = []
    slots = getattr(calibration, "slots", None)
    if slots is None:  # calibrated by its legs (the source was no humanoid): is it one?
        try:
            slots = find_slots(sk, calibration.points)[0]
        except ValueError:
            slots = None
    if slots is not None:
        for part, names in BODY_PARTS:
            missing = [sk.names[slots[k]] for k in names if k in slots and slots[k] not in mapped]
            if missing:
                out.append(f"{part} ({', '.join(missing)})")
        return out
    for leg in calibration.legs:
        if not mapped & set(leg.chain):
            out.append(f"the leg of {sk.names[leg.contact]}")
    chest = getattr(calibration, "chest", None)  # a skeleton without legs has none
    if chest is not None and chest not in mapped:
        out.append(f"spine ({sk.names[chest]})")
    return out


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
