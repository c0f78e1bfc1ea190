"""The plain progress lines (a log, CI) for every kind of entry, a lost task's included."""
import io

from rigedit.batch.progress import BatchProgress
from rigedit.batch.runner import _lost_entry
from rigedit.batch.tasks import check_options, plan


def test_a_lost_task_is_one_progress_line_not_a_crash(tmp_path):
    # its entry's seconds is None: "{None:.1f}" raised TypeError and stopped the batch
    tasks = plan("noop", [tmp_path / "a.bvh", tmp_path / "b.bvh"], tmp_path,
                 check_options("noop", {}))
    stream = io.StringIO()
    bar = BatchProgress(2, stream=stream)
    bar.update(_lost_entry(tasks[0], RuntimeError("KilledWorker: gone")))
    bar.update({"task": tasks[1]["id"], "status": "ok", "seconds": 0.25})
    lines = stream.getvalue().splitlines()
    assert len(lines) == 2
    assert lines[0].startswith(f"[1/2] {tasks[0]['id']}: failed (its worker died")
    assert "no time; done 0, failed 1, remaining 1" in lines[0]
    assert "0.2 s; done 1, failed 1, remaining 0" in lines[1]


def test_a_deep_path_does_not_push_the_problem_out_of_the_one_line_error(tmp_path):
    # the error was cut at 300 characters: a 400-character path left only the path
    from batch_helpers import broken_bvh
    from rigedit.batch.jobs import run_task

    deep = tmp_path.joinpath(*["a_rather_long_folder_name"] * 16)
    deep.mkdir(parents=True)
    entries = []
    for folder in (tmp_path, deep):
        (task,) = plan("retarget", [broken_bvh(folder)], tmp_path,
                       check_options("retarget", {"to": ["humanoid"], "thumbnails": False}))
        entries.append(run_task(task))
    short, long_ = (e["error"] for e in entries)
    problem = short.split("broken.bvh: ", 1)[1]
    assert len(str(deep)) > 400 and len(long_) <= 300 and "\n" not in long_
    assert long_.endswith(problem) and long_.startswith(str(tmp_path)[:100])


def test_a_missing_clip_error_names_what_was_wanted(tmp_path):
    # was "expected a clip , got none" / "expected a clip nope, got clips ..."
    from rigedit.batch.jobs import run_task

    (task,) = plan("convert", ["humanoid"], tmp_path,
                   check_options("convert", {"to": "bvh", "clip": "nope", "thumbnails": False}))
    error = run_task(task)["error"]
    assert error.startswith("humanoid") and "expected the clip 'nope', got clips " in error
    assert "walk" in error
