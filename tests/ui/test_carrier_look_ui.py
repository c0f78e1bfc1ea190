"""The editor draws the quadruped's carrier root thin and dim: its line on the overlay over the
mesh a third of the bones' width, its sphere in the carrier colour."""
import numpy as np
import pytest

pytestmark = [pytest.mark.ui]

from rigedit.render import joint_glyphs as jg  # noqa: E402


def test_the_editor_draws_the_carrier_thin_and_dim(window):
    view = window.scene_view
    scene = view.scene
    root = window.document.rig.skeleton.index["root"]
    assert scene.carriers[root]
    props = view.overlay.GetViewProps()
    assert props.IsItemPresent(scene.carrier_actor) and props.IsItemPresent(scene.bone_actor)
    assert scene.carrier_actor.GetProperty().GetLineWidth() == pytest.approx(4 / 3)
    assert scene.bone_actor.GetProperty().GetLineWidth() == 4
    np.testing.assert_allclose(view.gizmos.glyphs.color_of(root), jg.CARRIER_COLOR, atol=1 / 255)
    pelvis = window.document.rig.skeleton.index["pelvis"]
    np.testing.assert_allclose(view.gizmos.glyphs.color_of(pelvis), jg.SPHERE_COLOR, atol=1 / 255)
