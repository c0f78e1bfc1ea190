"""Where the tasks run: Dask's distributed scheduler, never one of ours.

- Local by default: ``distributed.LocalCluster(n_workers=N, threads_per_worker=1,
  processes=True)``, one worker process per core, started and stopped here.
- ``scheduler="tcp://HOST:PORT"``: a running cluster (``dask scheduler`` / ``dask worker``,
  dask-jobqueue, dask-kubernetes), reached with ``Client(address, timeout=...)``; one that
  does not answer within ``timeout`` seconds is a :class:`BatchUsageError`.

A worker that dies while running a task (killed, out of memory: the nanny restarts it) has
the task given to another worker by the scheduler; once its worker died
``distributed.scheduler.allowed-failures`` + 1 times the task errs with ``KilledWorker``. The
local cluster's scheduler is made with allowed-failures 1 (retried once, then failed); a
running scheduler keeps its own setting (said in one line when it is not 1).
"""
from __future__ import annotations

import logging
import math
import os
import uuid
from pathlib import Path

from .inputs import BatchUsageError

__all__ = ["Engine", "LOST"]

#: The task's worker died more often than the scheduler retries (``KilledWorker``).
LOST = "lost"


def _probe(path):
    """On a worker: whether it sees the probe file the client wrote into OUTDIR."""
    return os.path.isfile(path)


def _warm(modules):
    """On a worker: import the task code once, before the first task's clock starts."""
    import importlib

    for name in modules:
        try:
            importlib.import_module(name)
        except ImportError:   # the tasks that need it say so in their entries
            pass
    return os.getpid()


class Engine:
    """A Dask client on a local or a running cluster (a context manager: closed on exit).

    Parameters
    ----------
    workers : int, optional
        Local worker processes (default: one per core). Not with ``scheduler``.
    scheduler : str, optional
        Address of a running scheduler.
    timeout : float
        Seconds to wait for a scheduler to answer and for its first worker.
    say : callable(str)
        Where the engine's one-line notes go (the dashboard, the retry setting).
    warm : tuple of str
        Modules every worker imports when it starts (the tasks' code, the renderer).
    """

    def __init__(self, workers=None, scheduler=None, timeout=5.0, say=None, warm=()):
        if workers is not None and scheduler is not None:
            raise BatchUsageError("--workers and --scheduler: expected one of them (a running "
                                  "cluster has its own workers)")
        if workers is not None and not (isinstance(workers, int) and 1 <= workers <= 1024):
            raise BatchUsageError(f"--workers: expected a number of processes from 1 to 1024, "
                                  f"got {workers!r}")
        try:
            seconds = float(timeout)
        except (TypeError, ValueError):
            seconds = math.nan
        if not (math.isfinite(seconds) and 0 < seconds <= 86400):
            raise BatchUsageError(f"--timeout: expected seconds from more than 0 to 86400, "
                                  f"got {timeout!r}")
        self.workers, self.scheduler, self.timeout = workers, scheduler, seconds
        self.say = say or (lambda line: None)
        self.cluster = self.client = None
        self.futures = []
        self.warm = tuple(warm)

    def __enter__(self):
        return self.start()

    def start(self, tasks=None):
        """Start the local cluster or connect to the scheduler; returns self.

        ``tasks``: how many will run; a local cluster starts no more worker processes than
        that (each imports rigedit and the renderer: 3 files on a 64-core machine are not
        worth 64 processes)."""
        import dask
        import distributed

        if self.scheduler is None:
            n = self.workers or os.cpu_count() or 1
            n = min(n, tasks) if tasks else n
            with dask.config.set({"distributed.scheduler.allowed-failures": 1}):
                self.cluster = distributed.LocalCluster(
                    n_workers=n, threads_per_worker=1,
                    processes=True, dashboard_address=":0", silence_logs=logging.CRITICAL)
            self.client = distributed.Client(self.cluster)
        else:
            self._connect(distributed)
        self.client.run(_warm, self.warm)
        return self

    def _connect(self, distributed):
        try:
            self.client = distributed.Client(self.scheduler, timeout=self.timeout)
        except Exception as exc:   # also a transport this Dask lacks (ucx://: TypeError)
            raise BatchUsageError(f"{self.scheduler}: the scheduler does not answer within "
                                  f"{self.timeout:g} s ({' '.join(str(exc).split())[:160]})"
                                  ) from None
        try:
            self.client.wait_for_workers(1, timeout=self.timeout)
        except (OSError, TimeoutError):
            self.close()
            raise BatchUsageError(f"{self.scheduler}: the scheduler has no worker (none joined "
                                  f"within {self.timeout:g} s)") from None
        services = self.client.scheduler_info().get("services", {})
        if "dashboard" in services:
            self.say(f"dashboard: {self.client.dashboard_link}")
        tries = self.client.run_on_scheduler(_allowed_failures)
        if tries != 1:
            self.say(f"note: this scheduler retries a task whose worker died {tries} times "
                     f"(its distributed.scheduler.allowed-failures), not once")

    def __exit__(self, *exc):
        self.close()

    def close(self):
        """Cancel what is still queued or running, then close the client and a local
        cluster (its worker processes end)."""
        if self.client is not None:
            try:
                if self.futures:
                    self.client.cancel(self.futures, force=True)
                self.client.close()
            finally:
                self.client = None
                if self.cluster is not None:
                    self.cluster.close()
                    self.cluster = None

    def check_outdir(self, outdir):
        """``BatchUsageError`` unless every worker sees ``outdir`` (a cluster needs a shared
        file system): the client writes a probe file there and each worker stats it."""
        probe = Path(outdir) / f".rigedit-batch-probe-{uuid.uuid4().hex}"
        probe.write_bytes(b"")
        try:
            seen = self.client.run(_probe, str(probe))
        finally:
            probe.unlink()
        blind = sorted(w for w, ok in seen.items() if not ok)
        if blind:
            raise BatchUsageError(f"{outdir}: {len(blind)} of {len(seen)} workers cannot see "
                                  f"this folder ({', '.join(blind[:3])}); the cluster needs a "
                                  "file system shared with this machine at the same path")
        return len(seen)

    def map(self, fn, tasks):
        """Submit ``fn(task)`` for every task; yield ``(task, result, exception)`` as each
        ends (``exception`` is the ``KilledWorker`` of a task whose workers died)."""
        import distributed

        run = uuid.uuid4().hex[:8]   # a scheduler may still hold an older run's keys
        keys = [f"{task['id']}-{run}" for task in tasks]
        by_key = dict(zip(keys, tasks))
        # one submission and results gathered in batches: a round trip per task cost ~20 ms
        self.futures = self.client.map(fn, list(tasks), key=keys, pure=False)
        done = distributed.as_completed(self.futures, with_results=True, raise_errors=False)
        for fut, result in done:
            task = by_key[fut.key]
            if fut.status == "error":   # KilledWorker; the task's own errors are in its entry
                yield task, None, fut.exception()
            else:
                yield task, result, None
            fut.release()


def _allowed_failures(dask_scheduler):
    return dask_scheduler.allowed_failures
