"""glTF and rig folders: bind matrices and CUBICSPLINE tangents survive a folder save."""
from __future__ import annotations

import json

import numpy as np
import pytest

from gltf_builder import two_bone
from rigedit.errors import RigFileError
from rigedit.io.gltf_read import load_gltf
from test_gltf import sample_path

def test_rig_folder_keeps_gltf_bind_matrices(tmp_path):
    """CesiumMan binds elsewhere than its rest pose: a rig folder stores the bind matrices,
    so the reloaded rig skins every frame the same."""
    import rigedit

    rig = load_gltf(sample_path("CesiumMan.glb"))
    rest_fk = rig.skeleton.forward(rig.skeleton.rest_local_matrices())
    assert not np.allclose(rest_fk, rig.skeleton.bind_matrices, atol=1e-4)
    rigedit.save_rig(rig, tmp_path / "cesium")
    back = rigedit.load_rig(tmp_path / "cesium")
    assert "bind_matrix" in (tmp_path / "cesium" / "skeleton.json").read_text()
    np.testing.assert_allclose(back.skeleton.inverse_bind_matrices,
                               rig.skeleton.inverse_bind_matrices, atol=1e-12)
    clip = rig.clips["animation_0"]
    for t in np.linspace(0, clip.duration, 13):
        np.testing.assert_allclose(back.skin(back.clips["animation_0"].sample(t)),
                                   rig.skin(clip.sample(t)), atol=1e-6)


def test_bad_bind_matrix_in_skeleton_json(tmp_path):
    from rigedit.io.skeleton_json import load_skeleton

    path = tmp_path / "skeleton.json"
    path.write_text(json.dumps({"joints": [{"name": "a", "parent": None,
                                            "bind_matrix": [[1, 0, 0, 0]] * 4}]}))
    with pytest.raises(RigFileError, match="'bind_matrix'") as info:
        load_skeleton(path)
    assert str(path) in str(info.value)


def test_rig_folder_keeps_cubic_spline_tangents(tmp_path):
    import rigedit

    builder, _ = two_bone(interpolation="CUBICSPLINE")
    rig = load_gltf(builder.write(tmp_path / "a.glb"))
    rigedit.save_rig(rig, tmp_path / "folder")
    back = rigedit.load_rig(tmp_path / "folder")
    a, b = rig.clips["bend"].tracks[("tip", "rotation")], back.clips["bend"].tracks[("tip",
                                                                                     "rotation")]
    assert b.interpolation == "cubic_spline"
    np.testing.assert_allclose(b.tangents, a.tangents, atol=1e-9)
    for t in np.linspace(0, 1, 21):
        np.testing.assert_allclose(b.sample(t), a.sample(t), atol=1e-8)


def test_moving_a_joint_of_a_mesh_bound_in_its_own_frame():
    """Edit mode on CesiumMan (bound Z up, shown Y up): the joint lands where it was dragged
    in the view, every joint keeps its bind-to-rest map, so the skin at rest does not jump."""
    from rigedit.editor.document import skeleton_with_moved_joint

    rig = load_gltf(sample_path("CesiumMan.glb"))
    sk = rig.skeleton
    j = sk.index["Skeleton_arm_joint_L__3_"]
    rest = sk.forward(sk.rest_local_matrices())
    head = rest[j, :3, 3] + [0.0, 0.05, 0.0]
    new = skeleton_with_moved_joint(sk, j, head)
    new_rest = new.forward(new.rest_local_matrices())
    np.testing.assert_allclose(new_rest[j, :3, 3], head, atol=1e-12)
    others = np.arange(len(sk)) != j
    np.testing.assert_allclose(new_rest[others, :3, 3], rest[others, :3, 3], atol=1e-12)
    np.testing.assert_allclose(new_rest @ np.linalg.inv(new.bind_matrices),
                               rest @ np.linalg.inv(sk.bind_matrices), atol=1e-9)
