"""The decimated proxy of a big mesh carries the mesh's morph targets."""
import numpy as np
import pytest

pytest.importorskip("pyvista")

from builders import cylinder_rig  # noqa: E402
from morph_builders import add_targets  # noqa: E402
from rigedit.model.kinematics import skinning_matrices  # noqa: E402
from rigedit.render.proxy import build_proxy  # noqa: E402


def test_the_proxy_skins_its_vertices_with_the_full_meshs_morphs():
    rig = add_targets(cylinder_rig())
    proxy = build_proxy(rig.binding, rig.faces, target_faces=300)
    assert len(proxy.vertices) < len(rig.vertices)
    assert proxy.binding.morphs.names == rig.morphs.names
    pose = rig.clips["bend"].sample(0.5, out=rig.rest_pose())
    palette = skinning_matrices(rig.skeleton, rig.joint_matrices(pose))
    rig.binding.set_morph_weights([0.8, 0.4])
    proxy.binding.set_morph_weights(rig.binding.morph_weights)
    full = rig.binding.skin(palette, backend="numpy").copy()
    got = proxy.binding.skin(palette, backend="numpy")
    # decimation keeps a subset of the vertices in place: each is its source vertex
    np.testing.assert_allclose(got, full[proxy.source], atol=1e-5)
    assert np.abs(full[proxy.source] - rig.skin(pose, morph_weights=[0, 0])[proxy.source]
                  ).max() > 0.05                         # the morphs moved them
