"""A real Dask cluster on 127.0.0.1: ``dask scheduler`` and two ``dask worker`` processes,
a batch through ``--scheduler``, one worker killed (SIGKILL) in the middle. Every output
exists and loads, the manifest lists every task once, nothing is left half written, and a
``--resume`` run does nothing. And a task whose workers die every time is one failed row."""
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

import rigedit
from batch_helpers import free_port, RIGEDIT, litter, make_motions, run_cli
from testpaths import REPO

DASK = str(Path(sys.executable).parent / "dask")


def _wait_port(port, proc, seconds=30):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        assert proc.poll() is None, "the scheduler ended"
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.1)
    raise AssertionError(f"nothing listens on {port}")


@pytest.fixture
def cluster():
    env = {**os.environ, "OMP_NUM_THREADS": "1",
           "DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES": "1"}
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    procs = [subprocess.Popen([DASK, "scheduler", "--host", "127.0.0.1", "--port", str(port),
                               "--no-dashboard"], **quiet)]
    try:
        _wait_port(port, procs[0])
        workers = [subprocess.Popen([DASK, "worker", address, "--nthreads", "1", "--no-nanny",
                                     "--no-dashboard", "--host", "127.0.0.1"], **quiet)
                   for _ in range(2)]
        procs += workers
        yield address, workers
    finally:
        for p in procs:   # the test's own processes; a graceful close only waits
            if p.poll() is None:
                p.kill()
            p.wait(10)


def _workers_done(out):
    """The workers (host:pid) of the task entries written so far in ``out``."""
    seen = set()
    for path in (out / "manifest").glob("*.json"):
        try:
            seen.add(json.loads(path.read_text())["worker"])
        except (OSError, ValueError, KeyError):   # being replaced: read again next time
            pass
    return seen


@pytest.mark.slow
def test_a_batch_on_a_real_cluster_survives_a_killed_worker(cluster, tmp_path):
    address, workers = cluster
    make_motions(tmp_path / "in", 10)
    out = tmp_path / "out"
    args = ["batch", "retarget", tmp_path / "in", "--to", "humanoid", "-o", out,
            "--scheduler", address, "--timeout", "20", "--no-thumbnails"]
    batch = subprocess.Popen(RIGEDIT + [str(a) for a in args], cwd=REPO,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    end = time.monotonic() + 90
    # some done, most to come, and by both workers: under load one worker can join late, and
    # killing it before it did a task leaves nothing of it to see
    while len(_workers_done(out)) < 2:
        assert batch.poll() is None and time.monotonic() < end, batch.communicate()
        time.sleep(0.05)
    workers[0].send_signal(signal.SIGKILL)
    stdout, stderr = batch.communicate(timeout=120)
    assert batch.returncode == 0, stderr
    index = json.loads((out / "manifest.json").read_text())["tasks"]
    assert len(index) == 10 and len({e["task"] for e in index}) == 10
    assert {e["status"] for e in index} == {"ok"}
    assert len({e["worker"] for e in index}) == 2   # both worked, one till it was killed
    for e in index:
        rig = rigedit.load_rig(out / e["outputs"][0])
        assert list(rig.clips)
    assert litter(out) == []
    again = run_cli(*args, "--resume")
    assert again.returncode == 0 and "10 tasks: 0 run, 10 skipped" in again.stdout
    assert json.loads((out / "manifest.json").read_text())["tasks"] == index


def _die(task):
    os._exit(3)   # the worker process dies as if killed or out of memory


@pytest.mark.slow
def test_a_task_whose_worker_dies_twice_is_recorded_lost(tmp_path):
    from rigedit.batch.engine import Engine
    from rigedit.batch.runner import _lost_entry

    task = {"id": "t", "job": "noop", "input": "x", "target": None, "settings": {},
            "outputs": [], "thumbnail": None}
    import cloudpickle

    cloudpickle.register_pickle_by_value(sys.modules[__name__])   # workers need not import us
    t0 = time.monotonic()
    with Engine(workers=2) as engine:
        ((got, result, exc),) = list(engine.map(_die, [task]))
    assert result is None and type(exc).__name__ == "KilledWorker"
    entry = _lost_entry(got, exc)
    assert entry["status"] == "failed" and entry["failure"] == "lost"
    assert "died" in entry["error"] and "\n" not in entry["error"]
    assert time.monotonic() - t0 < 60


@pytest.mark.slow
def test_ctrl_c_stops_the_workers_and_leaves_a_consistent_manifest(tmp_path):
    import psutil

    make_motions(tmp_path / "in", 24)
    out = tmp_path / "out"
    batch = subprocess.Popen(RIGEDIT + ["batch", "retarget", str(tmp_path / "in"), "--to",
                                        "humanoid", "-o", str(out), "--workers", "2",
                                        "--no-thumbnails"],
                             cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    end = time.monotonic() + 90
    while len(list((out / "manifest").glob("*.json"))) < 3:
        assert batch.poll() is None and time.monotonic() < end, batch.communicate()
        time.sleep(0.05)
    children = psutil.Process(batch.pid).children(recursive=True)
    assert len(children) >= 2   # the workers (and their nannies)
    batch.send_signal(signal.SIGINT)
    t0 = time.monotonic()
    stdout, stderr = batch.communicate(timeout=60)
    assert batch.returncode == 130, stderr
    assert time.monotonic() - t0 < 20
    assert "interrupted by SIGINT" in stderr and "Traceback" not in stderr
    assert psutil.wait_procs(children, timeout=10)[1] == []   # every worker ended
    entries = sorted((out / "manifest").glob("*.json"))
    assert 3 <= len(entries) < 24
    for path in entries:
        entry = json.loads(path.read_text())
        assert entry["status"] == "ok" and (out / entry["outputs"][0]).is_file()
    index = json.loads((out / "manifest.json").read_text())["tasks"]
    assert len(index) == len(entries)
    assert litter(out) == []
    assert "not run (the batch was stopped)" in (out / "report.html").read_text()
