"""Quadrupeds of other proportions, rest poses and joint names, built from the bundled one
(for tests/test_retarget_quadruped.py and benchmarks/bench_retarget.py; numpy only)."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from rigedit.model import Skeleton
from rigedit.rig import Rig

LEG_PARTS = ("fore_lower", "fore_cannon", "fore_hoof", "hind_shin", "hind_cannon", "hind_hoof")
NECK = ("neck_2", "neck_3", "head")


def variant(skeleton, scale=1.0, legs=1.0, neck=1.0, bend=0.0, fore=1.0, pitch=0.0,
            rename=None):
    """A changed copy of the bundled quadruped's skeleton, standing on y = 0 again.

    Parameters
    ----------
    skeleton : Skeleton
        The bundled quadruped's.
    scale : float
        Every offset (and tail) times this.
    legs, neck : float
        The leg bones below the shoulder and hip joints, and the neck and head offsets,
        times these (before ``scale``).
    fore : float
        The fore legs' bones below the shoulder joints times this too.
    pitch : float
        Degrees the rest pose turns the spine at ``spine_1`` about +X (positive lowers the
        front), so that fore legs of another length can stand on the floor too.
    bend : float
        Degrees the rest pose turns the fore legs forward at the shoulder and the hind legs
        back at the hip (about +X), and the cannons half as much the other way.
    rename : callable, optional
        New name of each joint.

    Returns
    -------
    Rig
        Without a mesh and clips.
    """
    sk = skeleton
    factor = np.full(len(sk), scale)
    for name in sk.names:
        base = name.rsplit("_", 1)[0] if name.endswith(("_L", "_R")) else name
        if base in LEG_PARTS:
            factor[sk.index[name]] *= legs * (fore if base.startswith("fore") else 1.0)
        if base in NECK:
            factor[sk.index[name]] *= neck
    trans = sk.rest_translation * factor[:, None]
    rot = sk.rest_rotation.copy()
    for side in "LR":
        for name, deg in ((f"fore_upper_{side}", bend), (f"hind_thigh_{side}", -bend),
                          (f"fore_cannon_{side}", -bend / 2), (f"hind_cannon_{side}", bend / 2)):
            j = sk.index[name]
            rot[j] = (Rotation.from_euler("x", deg, degrees=True)
                      * Rotation.from_quat(rot[j])).as_quat()
    j = sk.index["spine_1"]
    rot[j] = (Rotation.from_euler("x", pitch, degrees=True) * Rotation.from_quat(rot[j])).as_quat()
    names = [rename(n) for n in sk.names] if rename else list(sk.names)
    new = Skeleton(names, sk.parents, trans, rot, sk.rest_scale, deform=sk.deform)
    old_m, new_m = sk.bind_matrices, new.bind_matrices
    tails = np.full_like(sk.tails, np.nan)
    for j in np.flatnonzero(np.all(np.isfinite(sk.tails), axis=1)):
        local = (np.linalg.inv(old_m[j]) @ np.r_[sk.tails[j], 1.0])[:3] * factor[j]
        tails[j] = (new_m[j] @ np.r_[local, 1.0])[:3]
    # the ground-level root (joint 0) stays where it is
    points = np.r_[new_m[1:, :3, 3], tails[np.all(np.isfinite(tails), axis=1)]]
    trans[1, 1] -= points[:, 1].min()  # the pelvis (under the ground-level root) down or up
    new = Skeleton(names, sk.parents, trans, rot, sk.rest_scale, deform=sk.deform,
                   tails=tails - [0.0, points[:, 1].min(), 0.0])
    return Rig(new, np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), name="variant")


#: Name the variants in the benchmark and the tests.
VARIANTS = {
    "long legs, short neck": dict(legs=1.3, neck=0.6),
    "small (x0.6), bent rest legs": dict(scale=0.6, bend=20.0),
    "big (x1.5), short legs": dict(scale=1.5, legs=0.8),
}


#: Fore legs of another length than the hind ones (a hyena, a giraffe): fore factor, the
#: rest's spine turned (:func:`level_pitch`) so all four hooves stand on the floor.
FORE = {"fore legs x0.8, rest sloping down": 0.8, "fore legs x1.25, rest sloping up": 1.25}


def fore_variant(skeleton, fore):
    """:func:`variant` with fore legs ``fore`` times as long, standing on all four."""
    return variant(skeleton, fore=fore, pitch=level_pitch(skeleton, fore=fore))


def renamed(name):
    """Other joint names: ``pelvis`` -> ``Q_Pelvis``, ``fore_upper_L`` -> ``Q_ForeUpper.l``."""
    side = ""
    if name.endswith(("_L", "_R")):
        name, side = name[:-2], "." + name[-1].lower()
    return "Q_" + "".join(w.capitalize() for w in name.split("_")) + side


def level_pitch(skeleton, **kw):
    """The ``pitch`` (degrees) at which a variant's fore and hind hooves stand on one level."""
    from scipy.optimize import brentq

    def gap(deg):
        sk = variant(skeleton, pitch=deg, **kw).skeleton
        y = sk.bind_matrices[:, 1, 3]
        return min(y[sk.index["fore_hoof_L"]], y[sk.index["fore_hoof_R"]]) - \
            min(y[sk.index["hind_hoof_L"]], y[sk.index["hind_hoof_R"]])
    return brentq(gap, -40.0, 40.0, xtol=1e-6)
