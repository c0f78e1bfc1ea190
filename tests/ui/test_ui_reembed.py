"""File > Re-embed around the joints I moved, in the real window under Xvfb: a joint moved in
bind mode (the rest move a drag ends with) is pinned where it was put and the others are
placed again in a background job; nothing moved, or a character not auto-rigged, is a status
message and no job.
"""
import numpy as np
import pytest

pytestmark = pytest.mark.ui

import rigedit  # noqa: E402

from ui_window_fixture import editor_window, menu_action  # noqa: E402


@pytest.fixture(scope="module")
def little_man():
    """The bundled humanoid's mesh decimated to about 3,000 triangles, auto-rigged (idw
    weights, no clips: quick)."""
    import pyvista as pv

    from rigedit.render.proxy import faces_to_vtk

    rig = rigedit.load_rig("humanoid")
    mesh = pv.PolyData(rig.vertices.copy(), faces_to_vtk(rig.faces))
    mesh = mesh.decimate(0.94).triangulate().clean()
    v = np.asarray(mesh.points, float)
    f = np.asarray(mesh.faces).reshape(-1, 4)[:, 1:]
    return v, f


def _autorigged(little_man):
    rig = rigedit.autorig(little_man, up="y", forward="z", weights="idw", clips=False)
    rig.name = "little man"
    return rig


def _heads(rig):
    return rig.joint_matrices(rig.rest_pose())[:, :3, 3]


def test_reembed_pins_the_moved_joint_and_places_the_others(qtbot, little_man):
    rig = _autorigged(little_man)
    with editor_window(qtbot, rig) as w:
        doc = w.document
        w.set_mode("edit")
        action = menu_action(w, "File", "Re-embed around the joints I moved")
        action.trigger()                               # nothing moved yet
        assert w.job is None and doc.rig is rig
        assert "no joint moved" in w.statusBar().currentMessage()
        sk = doc.skeleton
        elbow, hand = sk.index["LeftForeArm"], sk.index["LeftHand"]
        before = _heads(rig)
        target = before[elbow] + [0.0, 0.04, 0.0]        # the user lifts the elbow
        job = w.rebind.move_joint(elbow, target)
        assert job is not None
        qtbot.waitUntil(lambda: w.job is None, timeout=60000)
        assert np.allclose(_heads(doc.rig)[elbow], target)
        action.trigger()
        assert w.job is not None
        qtbot.waitUntil(lambda: w.job is None, timeout=180000)
        new = doc.rig
        assert new is not rig, w.last_error
        heads = _heads(new)
        assert np.allclose(heads[elbow], target, atol=1e-6)     # pinned where it was put
        assert new.autorig_report.hints.keys() == {"LeftForeArm"}
        assert np.linalg.norm(heads[hand] - before[hand]) < 0.1  # the others placed again
        assert new.name == "little man" and doc.modified and doc.mode == "edit"
        msg = w.statusBar().currentMessage()
        assert msg.startswith("Re-embedded around LeftForeArm"), msg


def test_a_character_not_auto_rigged_is_a_status_message(qtbot):
    from rigedit.ui.fallback import demo_rig

    with editor_window(qtbot, demo_rig()) as w:
        menu_action(w, "File", "Re-embed around the joints I moved").trigger()
        assert w.job is None
        assert "not auto-rigged" in w.statusBar().currentMessage()
