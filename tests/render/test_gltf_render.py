"""The glTF surface in the 3D scene: the base colour texture through the UVs."""
from __future__ import annotations

import numpy as np
import pytest

from rigedit.io.gltf_read import load_gltf
from test_gltf import sample_path

pv = pytest.importorskip("pyvista")


def test_cesium_man_shows_its_texture_upright():
    from rigedit.render.scene import RigScene

    rig = load_gltf(sample_path("CesiumMan.glb"))
    plotter = pv.Plotter(off_screen=True, window_size=(320, 480))
    try:
        scene = RigScene(plotter, rig)
        scene.update(rig.rest_pose())
        assert scene.mesh_actor.GetTexture() is not None
        tc = scene.mesh.active_texture_coordinates
        np.testing.assert_allclose(tc[:, 1], 1.0 - rig.surface.uvs[:, 1], atol=1e-6)
        # framed on the skinned rest pose (Y up, 1.5 m), not the Z-up bind-space mesh
        lo, hi = scene.rest_points().min(axis=0), scene.rest_points().max(axis=0)
        assert hi[1] - lo[1] > 1.3 and hi[2] - lo[2] < 0.6
        image = plotter.screenshot(return_img=True)
        mesh_pixels = image.reshape(-1, 3).astype(int)
        # the texture's blue and green bands show (an untextured clay mesh has neither)
        blue = (mesh_pixels[:, 2] > mesh_pixels[:, 0] + 40) & (mesh_pixels[:, 2] > 120)
        green = (mesh_pixels[:, 1] > mesh_pixels[:, 0] + 30) & (mesh_pixels[:, 1] > mesh_pixels[:, 2])
        assert blue.sum() > 200 and green.sum() > 200
        scene.show_weights(np.ones(len(rig.vertices)))
        assert scene.mesh_actor.GetTexture() is None
        scene.show_weights(None)
        assert scene.mesh_actor.GetTexture() is not None
    finally:
        plotter.close()


def test_bounds_of_a_mesh_bound_in_its_own_frame():
    """CesiumMan's mesh is stored Z up and bound there; its rig stands 1.5 m tall along y."""
    rig = load_gltf(sample_path("CesiumMan.glb"))
    lo, hi = rig.bounds()
    assert 1.4 < rig.height() < 1.6 and hi[2] - lo[2] < 0.6
    assert np.ptp(rig.vertices[:, 2]) > 1.4          # the stored mesh itself is Z up
