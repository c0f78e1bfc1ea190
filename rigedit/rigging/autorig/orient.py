"""Which way is up, and which way does a character face? Guessed from the mesh alone.

Rigedit's frame is +Y up, the character facing +Z, its left +X. A mesh comes in any frame;
:func:`orient` returns the rotation into ours, from the user's ``up``/``forward`` when given,
else guessed, with how sure the guess is:

1. **Left-right axis**: characters are mirror-symmetric. The mirror plane's normal is the
   direction whose reflection (through the surface's centre) maps the surface onto itself
   best: scored on area-weighted surface samples by the mean distance of each reflected
   sample to the nearest sample, searched over a sphere of directions and refined. The
   principal axes alone do not do: a T-pose is about as wide as tall, so two of them are
   ill-defined.
2. **Vertical axis**, inside the mirror plane: the principal axes of the surface projected
   onto it. An upright template (a biped, taller than long) stands along the longer one, a
   horizontal template (a quadruped) along the shorter. Sure when one is at least
   :data:`SURE_ELONGATION` times the other.
3. **Up, not down**: legs are thin and the mass sits on them, so the centre of volume lies
   above the middle of the height (a standing human's at 55-60%). Sure when it is at least
   :data:`SURE_MASS` of the height off the middle.
4. **Forward, not back**: an upright figure's feet point forward, so the lowest slice of
   the mesh (the feet) reaches further forward than the slice just above it (ankles and
   shins). A quadruped's head and neck reach far ahead of its fore legs while its rump ends
   near the hind legs, so its legs (the lowest slice) stand behind the middle of its length.
   Sure when the offset is at least :data:`SURE_FORWARD` of the length scale.

A long body (a quadruped template) is stood on its feet first: all round the mirror plane,
the direction it stands on is the support line that its feet touch: contacts far apart
(fore and hind hooves), under the centre of volume, each group of them on both sides of the
mirror plane (left and right feet, not a tail or a chin on the middle), the most touched of
those lines by a clear lead. That direction is down, with no sign to guess; without one
the principal axes and the cues above decide (a long neck tilts the principal axes by tens
of degrees: 36 on the elk, so that guess is only "sure" along the file's axes and on level
ground there).

A mirror plane or a vertical within :data:`SNAP_DEGREES` of the file's axes is snapped to
them (files are almost always saved axis-aligned). Measured on the bundled meshes, cow,
homer, CesiumMan and RiggedFigure: all 24 axis-aligned turns of each recovered and sure; 80
random turns of each: all recovered within 5.5 degrees and sure, but one of the elk's (no
ground found: "not sure", and wrong).

The guess is not the last word: :func:`hypotheses` offers it with the frames it most often
confuses (up reversed, the other in-plane axis up, the axis-aligned frames near each) and
:mod:`.orient_search` lets the embedding's fit decide among them.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...model.transforms import tangents
from ...model.transforms import unit
from .ground import angle, find_ground, support_up
from .mirror import surface_samples, symmetry_plane, volume_centroid

__all__ = ["Orientation", "orient", "hypotheses", "check_axes", "parse_axis", "axis_name",
           "SNAP_DEGREES", "HYPOTHESES"]

SNAP_DEGREES = 5.0
SURE_ELONGATION = 1.25
SURE_MASS = 0.02
SURE_SPREAD = 0.05
END_SLICE = 0.03
SURE_GROUND_TURN = 10.0
SURE_FORWARD = 0.01
SURE_SYMMETRY = 0.03   # mean mirror mismatch, as a fraction of the size, for "symmetric"
#: Orientations :func:`hypotheses` offers at most (each costs an embedding, 1-2 s).
HYPOTHESES = 4
#: A guessed frame within this of an axis-aligned one also offers that one (files are
#: almost always saved along their axes; a long neck tilts the principal axes by tens of
#: degrees).
NEAR_AXES_DEGREES = 40.0

AXES = {"x": 0, "y": 1, "z": 2}


def parse_axis(text):
    """A unit vector (3,) from an axis string: ``"y"``, ``"+y"``, ``"-x"``.

    Raises
    ------
    ValueError
        Anything else.
    """
    s = str(text).strip().lower()
    sign = -1.0 if s.startswith("-") else 1.0
    s = s.lstrip("+-")
    if s not in AXES:
        raise ValueError(f"expected an axis such as y, -x or +z, got {text!r}")
    v = np.zeros(3)
    v[AXES[s]] = sign
    return v


def axis_name(v, tol=1e-6):
    """``"+y"``, ``"-x"``... for an axis-aligned unit vector; the rounded vector otherwise."""
    v = np.asarray(v, dtype=float)
    k = int(np.argmax(np.abs(v)))
    if abs(abs(v[k]) - 1.0) < tol:
        return ("+" if v[k] > 0 else "-") + "xyz"[k]
    return "(" + ", ".join(f"{c:.3f}" for c in v) + ")"


@dataclass
class Orientation:
    """The frame a mesh was read in, relative to rigedit's.

    Attributes
    ----------
    up, forward : (3,) float64
        Unit vectors in the input's coordinates.
    guessed : bool
        Whether anything was guessed (False when both were given).
    sure : bool
        Whether every guessed decision passed its margin (see the module notes).
    notes : dict[str, float]
        The margins measured: ``symmetry`` (mirror mismatch / size), ``elongation``,
        ``mass`` (centre of volume above the middle / height), ``forward``.
    """

    up: np.ndarray
    forward: np.ndarray
    guessed: bool = False
    sure: bool = True
    notes: dict = field(default_factory=dict)

    @property
    def rotation(self):
        """(3, 3) float64 taking input coordinates to rigedit's (rows: left, up, forward)."""
        return np.stack([np.cross(self.up, self.forward), self.up, self.forward])

    def describe(self):
        how = "given" if not self.guessed else ("guessed" if self.sure else
                                                "guessed, NOT SURE: check it or give --up/--forward")
        return f"up {axis_name(self.up)}, forward {axis_name(self.forward)} ({how})"


def _as_vector(v, what):
    if v is None:
        return None
    if isinstance(v, str):
        return parse_axis(v)
    v = np.asarray(v, dtype=np.float64).reshape(3)
    if not np.all(np.isfinite(v)) or np.linalg.norm(v) == 0:
        raise ValueError(f"expected a direction for {what}, got {v}")
    return unit(v)


def check_axes(up, forward):
    """``up`` and ``forward`` as unit vectors (None where not given).

    Raises
    ------
    ValueError
        Not axes or vectors, or both given and not at right angles.
    """
    up, forward = _as_vector(up, "up"), _as_vector(forward, "forward")
    if up is not None and forward is not None and abs(up @ forward) > 1e-6:
        raise ValueError(f"expected --up and --forward at right angles, got up "
                         f"{axis_name(up)} and forward {axis_name(forward)}")
    return up, forward


def _nearest_axis(v):
    """The signed coordinate axis within ``SNAP_DEGREES`` of ``v``, else None."""
    k = int(np.argmax(np.abs(v)))
    if np.degrees(np.arccos(min(1.0, abs(v[k])))) > SNAP_DEGREES:
        return None
    return np.eye(3)[k] * np.sign(v[k])


def _snap(up, forward):
    """The axis-aligned (up, forward) nearest to the given ones, when both are within
    ``SNAP_DEGREES``; None otherwise."""
    out = tuple(_nearest_axis(v) for v in (up, forward))
    if any(a is None for a in out) or abs(out[0] @ out[1]) > 0:
        return None
    return out


def _forward_cue(points, up, fwd, upright):
    """Signed evidence that ``fwd`` (not ``-fwd``) is forward, as a fraction of the body's
    size (see the module notes, step 4)."""
    t = points @ up
    lo, h = t.min(), max(np.ptp(t), 1e-12)
    along = points @ fwd
    if upright:
        feet = along[t < lo + 0.04 * h]
        shins = along[(t > lo + 0.08 * h) & (t < lo + 0.15 * h)]
        if len(feet) == 0 or len(shins) == 0:
            return 0.0
        return float((feet.mean() - shins.mean()) / h)
    legs = along[t < lo + 0.15 * h]
    if len(legs) == 0:
        return 0.0
    middle = 0.5 * (along.min() + along.max())
    return float((middle - legs.mean()) / max(np.ptp(along), 1e-12))


def _up_score(points, centre, up):
    """Evidence that ``up`` (not ``-up``) is up, in units of the sure margins, and the two
    cues (see the module notes, step 3); ``centre`` is the centre of volume."""
    t = points @ up
    lo, hi = t.min(), t.max()
    h = max(hi - lo, 1e-12)
    mass = (centre @ up - 0.5 * (lo + hi)) / h

    def spread(sl):
        flat = sl - np.outer(sl @ up, up)
        return np.linalg.norm(np.ptp(flat, axis=0)) / h if len(sl) > 1 else 0.0
    feet = spread(points[t < lo + END_SLICE * h]) - spread(points[t > hi - END_SLICE * h])
    return mass / SURE_MASS + feet / SURE_SPREAD, float(mass), float(feet)


def _up(points, centre, normal, size, vertical, aligned, upright, notes):
    """Up (3,) from the vertical estimate in the mirror plane, and whether it is sure; the
    margins go into ``notes`` (see the module notes, steps 2 and 3)."""
    snapped = False
    ground = None if upright else find_ground(points, normal, size, centre)
    if ground is not None:
        # a long body standing on its legs: the ground it stands on says which way is up,
        # no sign to guess
        notes["stands"] = 1.0
        along = _nearest_axis(-ground)
        return (along if along is not None and aligned is not None else -ground), True
    if aligned is not None:
        # a file saved along its axes: the vertical is an in-plane file axis when the
        # estimate is near one (a tall body), or, for a long body (a long neck tilts its
        # principal axes by tens of degrees), when the ground is level across that axis
        k = int(np.argmax(np.abs(vertical) * (np.abs(normal) < 0.5)))
        axis = np.eye(3)[k] * np.sign(vertical[k])
        snapped = angle(axis, vertical) <= SNAP_DEGREES if upright else any(
            support_up(points, normal, s * axis, size, level=centre) for s in (1.0, -1.0))
        if snapped:
            vertical = axis
    ups = [s * vertical if snapped else support_up(points, normal, s * vertical, size)
           for s in (1.0, -1.0)]
    scores = [_up_score(points, centre, u) for u in ups]
    k = int(scores[1][0] > scores[0][0])
    up = ups[k]
    notes["up"] = 0.5 * abs(scores[0][0] - scores[1][0])
    notes["mass"], notes["feet"] = scores[k][1:]
    notes["ground_turn"] = min(angle(up, vertical), angle(up, -vertical))
    # off the file's axes nothing pins a long body's vertical down but a ground it stands on
    sure = (notes["up"] >= 1.0 and notes["ground_turn"] <= SURE_GROUND_TURN
            and (upright or snapped))
    return up, sure


def orient(vertices, faces, upright=True, up=None, forward=None):
    """The rotation of a mesh into rigedit's frame, given or guessed (see the module notes).

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int
    upright : bool
        The template stands tall (a biped) rather than long (a quadruped).
    up, forward : str or (3,) float, optional
        Given axes (``"y"``, ``"-x"``, or vectors in the input's coordinates); the missing
        ones are guessed.

    Returns
    -------
    Orientation

    Raises
    ------
    ValueError
        ``up`` and ``forward`` given but not perpendicular, or not axes.
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    up, forward = check_axes(up, forward)
    if up is not None and forward is not None:
        return Orientation(up, forward, guessed=False, sure=True)
    points = surface_samples(vertices, faces)
    size = float(np.ptp(points, axis=0).max())
    normal, mismatch = symmetry_plane(points, size, up if up is not None else forward)
    notes = {"symmetry": mismatch}
    sure = mismatch <= SURE_SYMMETRY
    centre = volume_centroid(vertices, faces)
    aligned = _nearest_axis(normal)
    if aligned is not None:
        normal = aligned
    if up is None:
        if forward is not None:
            vertical = unit(np.cross(forward, normal))
        else:
            e1, e2 = tangents(normal)
            flat = np.c_[points @ e1, points @ e2]
            _, vecs = np.linalg.eigh(np.cov(flat.T))
            major, minor = (vecs[0, 1] * e1 + vecs[1, 1] * e2), (vecs[0, 0] * e1 + vecs[1, 0] * e2)
            ext = [np.subtract(*np.percentile(points @ a, [99.5, 0.5])) for a in (major, minor)]
            notes["elongation"] = float(ext[0] / max(ext[1], 1e-12))
            sure &= notes["elongation"] >= SURE_ELONGATION
            vertical = unit(major if upright else minor)
        up, up_sure = _up(points, centre, normal, size, vertical, aligned, upright, notes)
        sure &= up_sure
    if forward is None:
        fwd = unit(np.cross(normal, up))
        cue = _forward_cue(points, up, fwd, upright)
        notes["forward"] = abs(cue)
        sure &= abs(cue) >= SURE_FORWARD
        forward = fwd if cue >= 0 else -fwd
    up = unit(up - (up @ forward) * forward) if abs(up @ forward) > 1e-9 else up
    snapped = _snap(up, forward)
    if snapped is not None:
        up, forward = snapped
    return Orientation(up, forward, guessed=True, sure=bool(sure), notes=notes)


def _aligned(up, forward):
    """The axis-aligned frame nearest (up, forward) within ``NEAR_AXES_DEGREES``, or None."""
    def near(v):
        k = int(np.argmax(np.abs(v)))
        if np.degrees(np.arccos(min(1.0, abs(v[k])))) > NEAR_AXES_DEGREES:
            return None
        return np.eye(3)[k] * np.sign(v[k])
    a, b = near(up), near(forward)
    if a is None or b is None or abs(a @ b) > 0:
        return None
    return a, b


def hypotheses(vertices, faces, upright=True, up=None, forward=None, limit=HYPOTHESES):
    """Plausible orientations of a mesh, the guess of :func:`orient` first.

    The guess's mirror plane (the left-right axis) is the most reliable of its decisions;
    which of the two in-plane axes is vertical, and which way up and forward point, are
    where it goes wrong (a big head above the centre of volume, a cow's neck tilting its
    principal axes). So the hypotheses are: the guess; up reversed; the other in-plane axis
    up (either way); each with forward from the guess's cue (:func:`_forward_cue`), and the
    axis-aligned frame near each one that is off the file's axes. A long (quadruped)
    template also gets the guess with forward reversed (head and tail tell the embedding
    apart). Given axes stay: with ``up`` given only forward turns, with ``forward`` given
    only up. The embedding's fit decides among them (:mod:`.orient_search`).

    Returns
    -------
    list of Orientation
        At most ``limit``, distinct (no two frames within ``SNAP_DEGREES``), the guess first;
        ``[given]`` when both axes are given.
    """
    guess = orient(vertices, faces, upright=upright, up=up, forward=forward)
    if not guess.guessed:
        return [guess]
    given_up, given_fwd = check_axes(up, forward)
    points = surface_samples(np.asarray(vertices, dtype=np.float64),
                             np.asarray(faces, dtype=np.int64))
    g_up, g_fwd = guess.up, guess.forward
    left = np.cross(g_up, g_fwd)

    def with_cue(u):
        f = unit(np.cross(left, u))
        return u, (f if _forward_cue(points, u, f, upright) >= 0 else -f)
    frames = [(g_up, g_fwd)]
    if given_up is not None:
        frames += [(g_up, -g_fwd), (g_up, unit(np.cross(g_up, g_fwd))),
                   (g_up, -unit(np.cross(g_up, g_fwd)))]
    elif given_fwd is not None:
        frames += [(-g_up, g_fwd), (left, g_fwd), (-left, g_fwd)]
    else:
        if not upright:
            frames.append((g_up, -g_fwd))
        frames += [with_cue(-g_up), with_cue(g_fwd), with_cue(-g_fwd)]
    out = []
    for u, f in frames:
        for cand in ((u, f), _aligned(u, f)):
            if cand is None or len(out) >= limit:
                continue
            if any(angle(cand[0], o.up) < SNAP_DEGREES and angle(cand[1], o.forward)
                   < SNAP_DEGREES for o in out):
                continue
            if not out:
                out.append(guess)
            else:
                u, f = (np.asarray(c, dtype=np.float64) for c in cand)
                # the forward cue of this frame (signed: < 0 when it says the other way)
                out.append(Orientation(u, f, guessed=True, sure=False, notes={
                    "forward": _forward_cue(points, u, f, upright)}))
    return out
