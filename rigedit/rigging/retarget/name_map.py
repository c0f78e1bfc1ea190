"""Humanoid joint maps: slot to slot between two humanoids, then by name; what a map leaves
out.

The slots (``hips``, ``chest``, ``thigh_L``...) are found from each tree's shape
(:mod:`.slots`); joints and fingers pair by their names (:mod:`.joint_names`); maps are read
and written as JSON (:mod:`.map_files`). :func:`auto_map` puts these together, and
:func:`unmapped_parts` lists the limbs, spine and head a map leaves out. The names of those
three modules are importable from here too, as they were before they were split off.
"""
from __future__ import annotations

import numpy as np

# the names below were this module's before it was split (limbs imports _KNEE): kept here
from .joint_names import FINGERS, KNEE as _KNEE, finger_pairs, name_pairs, normalise_name
from .map_files import load_map, save_map
from .slots import LIMB_SLOTS, bend_index, find_slots

__all__ = ["normalise_name", "find_slots", "auto_map", "name_pairs", "load_map", "save_map",
           "bend_index", "interior_map", "finger_pairs", "FINGERS", "LIMB_SLOTS",
           "BODY_PARTS", "unmapped_parts"]


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
