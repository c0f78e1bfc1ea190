"""File > Auto-rig mesh through the real menu action and dialog under Xvfb (only the file
dialogs are replaced): the result opens as a new unsaved document in bind mode with the
orientation and stage times in the status bar; Cancel and a bad mesh keep the open document.

The success test runs the real :func:`rigedit.autorig` on a small closed humanoid mesh (the
bundled humanoid's mesh decimated) when it is installed; the cancel test uses a stand-in that
keeps reporting progress until cancelled, so the moment of the click does not matter.
"""
import threading
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

pytestmark = pytest.mark.ui

from PyQt5 import QtWidgets  # noqa: E402

import rigedit  # noqa: E402
from rigedit.io.mesh import load_mesh, save_obj  # noqa: E402
from rigedit.rig import Rig  # noqa: E402

from ui_window_fixture import answer_file_dialog, editor_window, menu_action  # noqa: E402


@pytest.fixture(scope="module")
def small_humanoid_obj(tmp_path_factory):
    """The bundled humanoid's mesh, decimated to about 3,000 triangles and turned to face
    +X (so the orientation is not the identity), as an OBJ file."""
    import pyvista as pv

    from rigedit.render.proxy import faces_to_vtk

    rig = rigedit.load_rig("humanoid")
    mesh = pv.PolyData(rig.vertices.copy(), faces_to_vtk(rig.faces))
    mesh = mesh.decimate(0.94).triangulate().clean()
    v = np.asarray(mesh.points, float)
    f = np.asarray(mesh.faces).reshape(-1, 4)[:, 1:]
    v = v[:, [2, 1, 0]] * [1, 1, -1]  # +Z facing becomes +X facing (a turn about Y)
    path = tmp_path_factory.mktemp("autorig") / "little_man.obj"
    save_obj(path, v, f)
    return path


def _open_dialog(w, qtbot):
    menu_action(w, "File", "Auto-rig mesh").trigger()
    dlg = w.autorig.dialog
    qtbot.waitUntil(dlg.isVisible)
    return dlg


def _fill(dlg, monkeypatch, mesh, template="humanoid", up=None, forward=None):
    asked = answer_file_dialog(monkeypatch, "getOpenFileName", mesh)
    dlg.mesh_browse.click()
    assert asked == ["Mesh to auto-rig"]
    dlg.template_combo.setCurrentText(template)
    dlg.set_axes(up, forward)


def _state(doc):
    return doc.rig, doc.mode, len(doc.undo_stack), doc.modified


@pytest.fixture
def window(qtbot):
    from rigedit.ui.fallback import demo_rig

    with editor_window(qtbot, demo_rig()) as w:
        yield w


def test_dialog_refuses_missing_mesh_and_parallel_axes(window, qtbot, monkeypatch,
                                                       small_humanoid_obj):
    dlg = _open_dialog(window, qtbot)
    assert not dlg.ok_button.isEnabled()        # no mesh yet
    _fill(dlg, monkeypatch, small_humanoid_obj, up="y", forward="-y")
    assert not dlg.ok_button.isEnabled()
    assert "different axes" in dlg.problem_label.text()
    dlg.set_axes("y", "x")
    assert dlg.ok_button.isEnabled()
    assert dlg.arguments() == {"mesh": str(small_humanoid_obj), "template": "humanoid",
                               "up": "y", "forward": "x"}
    # a template file: chosen by its own dialog; none chosen falls back to the bundled one
    answer_file_dialog(monkeypatch, "getOpenFileName", "")
    dlg.template_combo.setCurrentIndex(2)
    dlg.template_combo.activated.emit(2)
    assert dlg.template_combo.currentText() == "humanoid"
    skel = Path(rigedit.resolve_rig_path("quadruped")) / "skeleton.json"
    answer_file_dialog(monkeypatch, "getOpenFileName", skel)
    dlg.template_combo.setCurrentIndex(2)
    dlg.template_combo.activated.emit(2)
    assert dlg.arguments()["template"] == skel.parent   # a rig folder, by its skeleton.json
    dlg.reject()


def test_autorig_opens_new_unsaved_document_in_bind_mode(window, qtbot, monkeypatch,
                                                         small_humanoid_obj):
    w = window
    doc = w.document
    old = doc.rig
    calls = []
    real = rigedit.autorig

    def spy(mesh, **kwargs):
        calls.append((mesh, {k: v for k, v in kwargs.items() if k != "progress"}))
        return real(mesh, **kwargs)

    monkeypatch.setattr(rigedit, "autorig", spy)
    dlg = _open_dialog(w, qtbot)
    _fill(dlg, monkeypatch, small_humanoid_obj)   # orientation: guessed
    seen = []
    w.progress.valueChanged.connect(seen.append)
    dlg.ok_button.click()
    assert w.job is not None
    qtbot.waitUntil(lambda: w.job is None, timeout=180000)

    assert calls == [(str(small_humanoid_obj), {"template": "humanoid", "up": None,
                                                "forward": None})]
    rig = doc.rig
    assert rig is not old, w.last_error
    template = rigedit.load_rig("humanoid")
    assert rig.skeleton.names == template.skeleton.names
    v, _ = load_mesh(small_humanoid_obj)
    assert len(rig.vertices) == len(v)
    assert set(rig.clips) == set(template.clips)
    # the mesh faced +X: the character shown stands up and faces +Z as every rig does
    heads = rig.joint_matrices(rig.rest_pose())[:, :3, 3]
    at = {n: heads[rig.skeleton.index[n]] for n in
          ("Head", "Hips", "LeftHand", "RightHand", "LeftFoot", "LeftToeBase")}
    assert at["Head"][1] > at["Hips"][1] > at["LeftFoot"][1]
    assert at["LeftHand"][0] > at["RightHand"][0]
    assert at["LeftToeBase"][2] > at["LeftFoot"][2]
    # a new document: unsaved, no undo history, no folder; in bind mode at once
    assert doc.modified and w.windowTitle().endswith("*"), (w.windowTitle(), w.last_error)
    assert rig.path is None
    assert len(doc.undo_stack) == 0
    assert doc.mode == "edit" and w.edit_mode_action.isChecked()
    assert "EDIT" in w.mode_label.text()
    msg = w.statusBar().currentMessage()
    assert msg.startswith(f"Auto-rigged {small_humanoid_obj.name}"), msg
    assert "guessed" in msg and " s (" in msg, msg
    assert max(seen, default=0) > 0     # the bar moved
    # Save asks where (no folder of its own)
    asked = []
    monkeypatch.setattr(QtWidgets.QFileDialog, "getExistingDirectory",
                        staticmethod(lambda *a, **k: asked.append(a[1]) or ""))
    w.files.save()
    assert asked == ["Save rig into folder"]


def test_cancel_keeps_the_open_document(window, qtbot, monkeypatch, small_humanoid_obj):
    w = window
    doc = w.document
    before = _state(doc)
    started, stopped = threading.Event(), threading.Event()

    def slow_autorig(mesh, template="humanoid", up=None, forward=None, progress=None, **kw):
        started.set()
        try:
            for i in range(6000):   # at most a minute, reporting like a long embedding
                progress(i / 6000, "discrete search")
                time.sleep(0.01)
        finally:
            stopped.set()
        pytest.fail("the cancel did not reach autorig's progress callback")

    monkeypatch.setattr(rigedit, "autorig", slow_autorig, raising=False)
    dlg = _open_dialog(w, qtbot)
    _fill(dlg, monkeypatch, small_humanoid_obj, template="quadruped")
    dlg.ok_button.click()
    qtbot.waitUntil(started.is_set, timeout=10000)
    qtbot.waitUntil(lambda: "discrete search" in w.progress.format(), timeout=10000)
    assert w.cancel_button.isVisible()
    w.cancel_button.click()
    qtbot.waitUntil(lambda: w.job is None, timeout=10000)
    assert stopped.is_set()
    assert _state(doc) == before
    assert w.statusBar().currentMessage() == f"Auto-rigging {small_humanoid_obj.name}: cancelled"


def test_bad_mesh_keeps_the_open_document_and_names_the_file(window, qtbot, monkeypatch,
                                                             tmp_path):
    w = window
    doc = w.document
    before = _state(doc)
    bad = tmp_path / "broken_statue.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")   # a face beyond the vertices
    dlg = _open_dialog(w, qtbot)
    _fill(dlg, monkeypatch, bad)
    dlg.ok_button.click()
    qtbot.waitUntil(lambda: w.job is None, timeout=60000)
    assert _state(doc) == before
    assert "broken_statue.obj" in w.last_error
    assert "broken_statue.obj" in w.statusBar().currentMessage()


def test_status_line_from_report():
    from rigedit.rigging.autorig.orient import Orientation
    from rigedit.ui.autorig_dialog import describe_report

    report = SimpleNamespace(
        orientation=Orientation(np.array([0.0, 1, 0]), np.array([-1.0, 0, 0]), guessed=True),
        clips={"walk": "retargeted", "wave": "no arms found"},
        seconds={"load/check": 0.5, "embedding": 2.25, "embedding/search": 2.0,
                 "weights": 1.0, "total": 3.8})
    assert describe_report(report) == (
        "up +y, forward -x (guessed); clips left out: wave; 3.8 s (load/check 0.5 s, "
        "embedding 2.2 s, weights 1.0 s)")
    report.orientation.sure = False
    assert "NOT SURE" in describe_report(report)
    report.orientation.guessed = False
    assert "(given)" in describe_report(report)
    assert describe_report(None) == ""


def test_result_without_report_still_opens(window, qtbot, monkeypatch, small_humanoid_obj):
    # a stand-in autorig built from the interface: the window's side of the contract only
    w = window
    template = rigedit.load_rig("humanoid")

    def fake(mesh, template="humanoid", up=None, forward=None, progress=None, **kw):
        v, f = load_mesh(mesh)
        progress(0.5, "weights")
        return Rig(rigedit.load_rig(template).skeleton, v, f, weights_method="idw",
                   name=Path(mesh).stem, path=Path(mesh).parent)

    monkeypatch.setattr(rigedit, "autorig", fake, raising=False)
    dlg = _open_dialog(w, qtbot)
    _fill(dlg, monkeypatch, small_humanoid_obj)
    dlg.ok_button.click()
    qtbot.waitUntil(lambda: w.job is None, timeout=60000)
    assert w.document.rig.skeleton.names == template.skeleton.names, w.last_error
    assert w.document.rig.path is None    # never the mesh's folder: Save must ask
    assert w.document.modified and w.document.mode == "edit"


def test_not_sure_result_says_why_and_selects_the_joint_in_doubt(window, qtbot, monkeypatch,
                                                                 small_humanoid_obj):
    from rigedit.rigging.autorig.orient import Orientation

    w = window

    def fake(mesh, template="humanoid", up=None, forward=None, progress=None, **kw):
        v, f = load_mesh(mesh)
        rig = Rig(rigedit.load_rig(template).skeleton, v, f, weights_method="idw",
                  name=Path(mesh).stem)
        rig.autorig_report = SimpleNamespace(
            orientation=Orientation(np.array([0.0, 1, 0]), np.array([0.0, 0, 1]),
                                    guessed=True),
            clips={}, seconds={"total": 1.0}, sure=False,
            reasons=["the left arm or limb (LeftHand) shares a part of the mesh with another "
                     "limb", "Neck is off the middle plane"],
            doubtful=["LeftForeArm", "LeftHand", "Neck"])
        return rig

    monkeypatch.setattr(rigedit, "autorig", fake, raising=False)
    dlg = _open_dialog(w, qtbot)
    _fill(dlg, monkeypatch, small_humanoid_obj)
    dlg.ok_button.click()
    qtbot.waitUntil(lambda: w.job is None, timeout=60000)
    message = w.statusBar().currentMessage()
    assert "NOT SURE: the left arm or limb (LeftHand) shares" in message, message
    assert "(and 1 more)" in message
    assert w.document.mode == "edit"
    assert w.document.selection == w.document.rig.skeleton.index["LeftForeArm"]


def test_real_autorig_lets_the_cancel_through(small_humanoid_obj):
    # the editor's Cancel is an exception raised from the progress callback: autorig must
    # let it through (not turn it into a bad-input error), whatever stage it is in
    from rigedit.ui.jobs import Cancelled

    stages = []

    def progress(fraction, stage):
        stages.append(stage)
        if len(set(stages)) > 2:
            raise Cancelled()

    with pytest.raises(Cancelled):
        rigedit.autorig(str(small_humanoid_obj), template="humanoid", progress=progress)
    assert len(set(stages)) == 3
