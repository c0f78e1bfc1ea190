"""The edit-mode rest move (RestRebind) on its own: a real Document, and a stand-in for the
window's job runner that hands the worker's function and callbacks to the test, so that the
result can arrive when the test says. No window."""
from __future__ import annotations

import numpy as np
import pytest

from rigedit.editor.document import Document
from rigedit.ui import rebind as rebind_module
from rigedit.ui.fallback import demo_rig
from rigedit.ui.rebind import RestRebind


class FakeJob:
    def __init__(self, label, fn, done, cancelled):
        self.label, self.fn, self.done, self.cancelled = label, fn, done, cancelled
        self.is_cancelled = False

    def cancel(self):
        self.is_cancelled = True


@pytest.fixture
def setup(monkeypatch):
    doc = Document(demo_rig())
    binding = doc.rig.binding
    # the worker's weights: the current ones (the maths is tested elsewhere)
    monkeypatch.setattr(rebind_module, "compute_weights_for",
                        lambda vertices, skeleton, progress=None, faces=None:
                        (binding.indices.copy(), binding.weights.copy()))
    jobs, log = [], {"status": [], "refresh": 0, "undo_changed": 0}
    held = [False]

    def run_job(label, fn, done, cancelled):
        job = FakeJob(label, fn, done, cancelled)
        jobs.append(job)
        return job

    def current():
        return jobs[-1] if jobs and not getattr(jobs[-1], "finished", False) else None

    r = RestRebind(doc, run_job, current,
                   lambda: log.__setitem__("refresh", log["refresh"] + 1),
                   log["status"].append, lambda: held[0],
                   lambda: log.__setitem__("undo_changed", log["undo_changed"] + 1))
    return doc, r, jobs, log, held


def _finish(job):
    job.finished = True
    job.done(job.fn(lambda fraction: None))


def test_rest_move_is_one_undo_step_once_the_worker_is_done(setup):
    doc, r, jobs, log, _held = setup
    sk0 = doc.skeleton
    j = doc.skeleton.index["front_shin_L"]
    head = sk0.bind_matrices[j, :3, 3] + [0.0, 0.05, 0.0]
    job = r.move_joint(j, head)
    assert job is jobs[0] and job.label == "Re-binding after moving front_shin_L"
    assert doc.skeleton is sk0 and log["undo_changed"] == 1  # nothing applied yet
    assert r.undoable() is not None  # undo now would cancel it
    _finish(job)
    assert doc.skeleton is not sk0
    np.testing.assert_allclose(doc.skeleton.bind_matrices[j, :3, 3], head, atol=1e-12)
    assert doc.undo_stack.undo_label == "Move front_shin_L (rest)"
    assert "re-bound the skin" in log["status"][-1]
    assert r.undo() is not None and doc.skeleton is sk0  # a plain undo now


def test_a_second_move_while_one_runs_is_refused(setup):
    doc, r, jobs, log, _held = setup
    j = doc.skeleton.index["front_shin_L"]
    r.move_joint(j, doc.skeleton.bind_matrices[j, :3, 3] + 0.05)
    k = doc.skeleton.index["head"]
    assert r.move_joint(k, doc.skeleton.bind_matrices[k, :3, 3] + 0.05) is None
    assert len(jobs) == 1 and log["refresh"] == 1
    assert log["status"][-1].startswith("Busy with 'Re-binding after moving front_shin_L'")


def test_undo_while_running_cancels_and_the_late_result_is_not_applied(setup):
    doc, r, jobs, log, _held = setup
    sk0 = doc.skeleton
    j = doc.skeleton.index["front_shin_L"]
    job = r.move_joint(j, sk0.bind_matrices[j, :3, 3] + 0.05)
    assert r.undo() is None and job.is_cancelled
    assert log["status"][-1] == "Undo Move front_shin_L (rest): re-bind cancelled"
    _finish(job)  # the result was already on its way
    assert doc.skeleton is sk0 and len(doc.undo_stack) == 0
    assert "cancelled" in log["status"][-1]


def test_an_edit_made_meanwhile_means_undo_no_longer_cancels(setup):
    doc, r, jobs, _log, _held = setup
    j = doc.skeleton.index["front_shin_L"]
    job = r.move_joint(j, doc.skeleton.bind_matrices[j, :3, 3] + 0.05)
    doc.set_joint_euler(j, [10.0, 0.0, 0.0])  # a newer edit on the undo stack
    assert r.undoable() is None
    r.undo()  # undoes the rotation
    assert not job.is_cancelled


def test_result_for_a_replaced_rig_is_dropped(setup):
    doc, r, jobs, log, _held = setup
    j = doc.skeleton.index["front_shin_L"]
    job = r.move_joint(j, doc.skeleton.bind_matrices[j, :3, 3] + 0.05)
    other = demo_rig()
    doc.set_rig(other)
    _finish(job)
    assert doc.rig is other and len(doc.undo_stack) == 0
    assert "dropped: another rig was opened" in log["status"][-1]
