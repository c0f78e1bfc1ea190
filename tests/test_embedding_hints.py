"""Hints (``embed_skeleton(..., hints={joint: point})``): pinned joints are where the user put
them, the search places the others around them, and a bad hint is one error naming its joint.
"""
from __future__ import annotations

import numpy as np
import pytest

from rigedit.embedding import EmbeddingError, cd_j2j, embed_skeleton
from rigedit.embedding.hints import HintError
from test_embedding_stretch import HUMAN, stretched


def _embed(rig, vertices, **kw):
    return embed_skeleton(vertices, rig.faces, rig.skeleton,
                          template_mesh=(rig.vertices, rig.faces), **kw)


@pytest.fixture(scope="module")
def crouched(humanoid):
    """The humanoid skinned deep in a crouch with short arms held forward: far from the
    template's rest, so the unhinted embedding misplaces knees and elbows."""
    offsets = HUMAN["short arms"][0]
    angles = {"LeftUpLeg": [-70, 0, 0], "RightUpLeg": [-70, 0, 0], "LeftLeg": [100, 0, 0],
              "RightLeg": [100, 0, 0], "LeftFoot": [-30, 0, 0], "RightFoot": [-30, 0, 0],
              "LeftArm": [0, -60, -30], "RightArm": [0, 60, 30]}
    return stretched(humanoid, offsets, None, angles)


def test_hinted_joints_are_where_the_user_put_them_and_help_the_others(humanoid, crouched):
    vertices, truth = crouched
    sk = humanoid.skeleton
    diag = float(np.linalg.norm(np.ptp(vertices, axis=0)))
    pick = [j for j in range(len(sk)) if sk.parents[j] >= 0]
    free = _embed(humanoid, vertices)
    # what Mixamo asks for: chin (here the head), wrists, elbows, knees, groin (the hips)
    names = ["Head", "LeftHand", "RightHand", "LeftForeArm", "RightForeArm", "LeftLeg",
             "RightLeg", "Hips"]
    hints = {n: truth[sk.index[n]] for n in names}
    pinned = _embed(humanoid, vertices, hints=hints)
    for n in names:
        assert np.allclose(pinned.positions[sk.index[n]], hints[n]), n
    others = [j for j in pick if sk.names[j] not in names]
    before = cd_j2j(free.positions[others], truth[others], diag)
    after = cd_j2j(pinned.positions[others], truth[others], diag)
    assert after < 0.8 * before, (before, after)


def test_hinted_knees_keep_the_feet_where_the_mesh_has_them(humanoid, crouched):
    """A hinted inner joint (a knee) splits its chain: the foot is placed by the two halves'
    lengths from the knee, not under it by the template's straight leg (9% of the height
    forward when the halves kept a bone's direction term)."""
    vertices, truth = crouched
    sk = humanoid.skeleton
    diag = float(np.linalg.norm(np.ptp(vertices, axis=0)))
    hints = {n: truth[sk.index[n]] for n in ("LeftLeg", "RightLeg")}
    emb = _embed(humanoid, vertices, hints=hints)
    for n in ("LeftLeg", "RightLeg"):
        assert np.allclose(emb.positions[sk.index[n]], hints[n])
    for n in ("LeftFoot", "RightFoot"):
        j = sk.index[n]
        assert np.linalg.norm(emb.positions[j] - truth[j]) / diag < 0.04, n  # measured 0.023


def test_an_unknown_joint_is_one_error_naming_it(humanoid):
    with pytest.raises(HintError, match="'LeftElbow'.*no such joint"):
        _embed(humanoid, humanoid.vertices, hints={"LeftElbow": [0.0, 1.0, 0.0]})
    with pytest.raises(HintError, match="'lefthand'.*did you mean LeftHand"):
        _embed(humanoid, humanoid.vertices, hints={"lefthand": [0.0, 1.0, 0.0]})


def test_a_point_outside_the_mesh_is_one_error_naming_the_joint(humanoid):
    top = humanoid.vertices[:, 1].max()
    with pytest.raises(HintError, match="'Head'.*outside the mesh"):
        _embed(humanoid, humanoid.vertices, hints={"Head": [0.0, top + 0.5, 0.0]})
    with pytest.raises(HintError, match="'Head'.*finite"):
        _embed(humanoid, humanoid.vertices, hints={"Head": [0.0, np.nan, 0.0]})
    assert issubclass(HintError, ValueError) and not issubclass(HintError, EmbeddingError)
