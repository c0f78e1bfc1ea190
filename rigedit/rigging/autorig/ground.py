"""Where a character stands: the support line its feet touch, in its mirror plane.

Used by :mod:`.orient` to level the ground under an upright figure and to find which way a
long body (a quadruped) stands, all round.
"""
from __future__ import annotations

import numpy as np

from ...model.transforms import tangents
from ...model.transforms import unit

__all__ = ["support_up", "stands_on", "find_ground", "angle"]

GROUND_DEGREES = 20.0
GROUND_TOUCH = 0.005
GROUND_SPAN = 0.2
GROUND_LEAD = 1.5
FOOT_APART = 0.03


def angle(a, b):
    """Degrees between unit vectors."""
    return float(np.degrees(np.arccos(np.clip(np.dot(a, b), -1.0, 1.0))))


def support_up(points, normal, up, size, level=None):
    """``up`` turned in the mirror plane so that the ground is level. The ground is the line
    of support (in the mirror plane, within :data:`GROUND_DEGREES` of below) that most of the
    surface touches, within :data:`GROUND_TOUCH` of the size: the soles, the hooves; a line
    grazing a heel's curve or running from a hoof to the chin touches only points.

    With ``level`` (the centre of volume, (3,)), return instead whether ``up`` itself is
    level ground: the most touched line lies within a degree of it, its contacts lie apart
    (at least :data:`GROUND_SPAN` of the size: heel and toe, fore and hind hooves; not one
    point contact among ties), hold the body up (the centre of volume lies between them,
    seen from above), and are feet: each group of contacts (split where they lie more than
    :data:`GROUND_SPAN` / 4 apart) touches on both sides of the mirror plane, at least
    :data:`FOOT_APART` of the size off it, as left and right feet do, not at a chin or a tail
    on the middle."""
    e1, e2 = tangents(normal)
    flat = np.c_[points @ e1, points @ e2]
    down = -np.array([up @ e1, up @ e2])
    base = np.arctan2(down[1], down[0])
    best = None
    for span, step in ((np.radians(GROUND_DEGREES), np.radians(1.0)),
                       (np.radians(1.0), np.radians(0.1))):
        centre = base if best is None else best
        ang = centre + np.arange(-span, span + step / 2, step)
        d = np.c_[np.cos(ang), np.sin(ang)]
        proj = d @ flat.T                                   # (A, N)
        touch = (proj > proj.max(axis=1, keepdims=True) - GROUND_TOUCH * size).sum(axis=1)
        # ties go to the angle nearest the estimate
        pick = np.lexsort((np.abs(ang - centre), -touch))[0]
        best = ang[pick]
    found = unit(-(np.cos(best) * e1 + np.sin(best) * e2))
    if level is not None:
        return bool(angle(found, up) <= 1.0 and stands_on(points, flat, normal, size,
                                                             level, best))
    return found


def stands_on(points, flat, normal, size, centre, angle):
    """Whether the support line below, in direction ``angle`` in the mirror plane's
    coordinates ``flat`` (N, 2), is ground the body stands on (see :func:`support_up`)."""
    e1, e2 = tangents(normal)
    d = np.array([np.cos(angle), np.sin(angle)])
    along = np.array([-d[1], d[0]])
    proj = flat @ d
    touching = proj > proj.max() - GROUND_TOUCH * size
    contact = flat[touching] @ along
    c = np.array([centre @ e1, centre @ e2]) @ along
    if not (np.ptp(contact) >= GROUND_SPAN * size and contact.min() < c < contact.max()):
        return False
    side = points[touching] @ normal - np.median(points @ normal)
    order = np.argsort(contact)
    groups = np.split(order, np.flatnonzero(np.diff(contact[order]) >
                                            GROUND_SPAN / 4 * size) + 1)
    return all((side[g] > FOOT_APART * size).any() and (side[g] < -FOOT_APART * size).any()
               for g in groups)


def find_ground(points, normal, size, centre):
    """The direction, all round the mirror plane, on which the body stands (see
    :func:`support_up`): (3,) pointing down, or None. Each direction where the touching
    surface peaks is refined to a tenth of a degree and tested; of those that pass, the one
    most surface touches wins, and only when it touches at least :data:`GROUND_LEAD` times
    what any other (more than 10 degrees away) does: hind hooves with antler tips may hold
    an elk up too, but the four hooves touch more."""
    e1, e2 = tangents(normal)
    flat = np.c_[points @ e1, points @ e2]

    def touching(ang):
        proj = np.c_[np.cos(ang), np.sin(ang)] @ flat.T
        return (proj > proj.max(axis=1, keepdims=True) - GROUND_TOUCH * size).sum(axis=1)

    ang = np.radians(np.arange(0.0, 360.0, 1.0))
    touch = touching(ang)
    peak = (touch >= np.roll(touch, 1)) & (touch >= np.roll(touch, -1))
    found = []
    for a in ang[peak]:
        fine = a + np.radians(np.arange(-1.0, 1.05, 0.1))
        t = touching(fine)
        best = fine[np.argmax(t)]
        if stands_on(points, flat, normal, size, centre, best):
            found.append((int(t.max()), np.cos(best) * e1 + np.sin(best) * e2))
    if not found:
        return None
    found.sort(key=lambda x: -x[0])
    top, down = found[0]
    rivals = [n for n, d in found[1:] if angle(d, down) > 10.0]
    if rivals and top < GROUND_LEAD * max(rivals):
        return None
    return unit(down)


