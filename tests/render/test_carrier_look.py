"""A carrier root (a joint on the floor or at the origin that only moves the figure) is drawn
thin and dim: its line to the hips in an actor of its own, its sphere in the carrier colour;
a rig without one draws as before."""
from __future__ import annotations

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

from builders import cylinder_rig  # noqa: E402
from rigedit.render import joint_glyphs as jg  # noqa: E402
from rigedit.render import skeleton_actors as sa  # noqa: E402
from rigedit.render.scene import RigScene  # noqa: E402


@pytest.fixture
def plotter():
    p = pv.Plotter(off_screen=True, window_size=(200, 150))
    yield p
    p.close()


def _lines(actor):
    data = pv.wrap(actor.GetMapper().GetInput())
    return {tuple(c) for c in data.lines.reshape(-1, 3)[:, 1:]}


def _color(actor):
    return np.array(actor.GetProperty().GetColor())


@pytest.mark.parametrize("bold", [False, True])
def test_the_carrier_line_is_thin_and_dim(plotter, quadruped, bold):
    sk = quadruped.skeleton
    root, pelvis = sk.index["root"], sk.index["pelvis"]
    if bold:   # a skeleton without a mesh draws everything bolder, the carrier still thinner
        bones, actor, carrier = sa.add_bones(plotter, sk, bold=True, carriers=[True] +
                                             [False] * (len(sk) - 1))
    else:
        scene = RigScene(plotter, quadruped, show_skeleton=True)
        actor, carrier = scene.bone_actor, scene.carrier_actor
        assert scene.carriers[root] and scene.carriers.sum() == 1
    assert _lines(carrier) == {(root, pelvis)}
    assert (root, pelvis) not in _lines(actor) and len(_lines(actor)) == len(sk) - 2
    np.testing.assert_allclose(_color(carrier), pv.Color(sa.CARRIER_COLOR).float_rgb)
    np.testing.assert_allclose(_color(actor), pv.Color(sa.BONE_COLOR).float_rgb)
    assert carrier.GetProperty().GetLineWidth() < actor.GetProperty().GetLineWidth()
    # no bright dot at the carrier (the bones draw a dot per joint)
    dots = pv.wrap(actor.GetMapper().GetInput()).verts.reshape(-1, 2)[:, 1]
    assert root not in dots and set(dots) == set(range(len(sk))) - {root}
    # dim: a grey (the bones are a saturated blue) of middle lightness, between the editor's
    # dark background and the recorder's light one
    assert np.ptp(_color(carrier)) < 0.1 < 0.5 < np.ptp(_color(actor))
    dark, light = (np.mean(pv.Color(c).float_rgb) for c in ("#2b2f36", "#dadfe5"))
    assert dark + 0.25 < np.mean(_color(carrier)) < light - 0.25


def test_the_carrier_line_moves_with_the_bones_and_hides_with_them(plotter, quadruped):
    scene = RigScene(plotter, quadruped, show_skeleton=True)
    clip = quadruped.clips["walk"]
    model = scene.update(clip.sample(0.9))
    shown = pv.wrap(scene.carrier_actor.GetMapper().GetInput()).points
    np.testing.assert_allclose(shown, model[:, :3, 3], atol=1e-6)
    scene.set_skeleton_visible(False)
    assert not scene.carrier_actor.GetVisibility() and not scene.bone_actor.GetVisibility()
    scene.set_skeleton_visible(True)
    assert scene.carrier_actor.GetVisibility()


def test_a_rig_without_a_carrier_is_unchanged(plotter):
    rig = cylinder_rig()
    scene = RigScene(plotter, rig, show_skeleton=True)
    assert not scene.carriers.any() and scene.carrier_actor is None
    assert "rig-carrier-bones" not in plotter.actors
    assert _lines(scene.bone_actor) == {(0, 1), (1, 2)}
    assert pv.wrap(scene.bone_actor.GetMapper().GetInput()).n_verts == 3
    assert scene.bone_actor.GetProperty().GetLineWidth() == 3


def test_the_carrier_sphere_has_the_carrier_colour():
    pts = np.eye(3)
    glyphs = jg.JointGlyphs(pts, 0.1, deform=[False, True, False], carriers=[True, False, False])
    np.testing.assert_allclose(glyphs.color_of(0), jg.CARRIER_COLOR, atol=1 / 255)
    np.testing.assert_allclose(glyphs.color_of(1), jg.SPHERE_COLOR, atol=1 / 255)
    np.testing.assert_allclose(glyphs.color_of(2), jg.NON_DEFORMING_COLOR, atol=1 / 255)
    # dimmer (darker, greyer) than a joint's sphere, and than a non-deforming one's
    for other in (jg.SPHERE_COLOR, jg.NON_DEFORMING_COLOR):
        assert np.mean(jg.CARRIER_COLOR) < np.mean(other)
        assert np.ptp(jg.CARRIER_COLOR) < np.ptp(other)
    glyphs.set_state(selected=0)    # selected, it shows as selected all the same
    np.testing.assert_allclose(glyphs.color_of(0), jg.SELECTED_COLOR, atol=1 / 255)
    plain = jg.JointGlyphs(pts, 0.1)
    assert all(np.allclose(plain.color_of(j), jg.SPHERE_COLOR, atol=1 / 255) for j in range(3))
