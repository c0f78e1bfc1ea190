"""``rigedit.batch.run``: a job over many inputs, on Dask, with a manifest and a report."""
from __future__ import annotations

import contextlib
import os
import shutil
import sys
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

from .engine import LOST, Engine
from .inputs import BatchUsageError, expand_inputs
from .jobs import one_line, run_task
from .manifest import MANIFEST_DIR, Manifest, rigedit_version
from .progress import BatchProgress
from .report import write_report
from .tasks import THUMBS_DIR, check_options, plan

__all__ = ["run", "Summary", "prepare_outdir", "outdir_path", "remove_temps"]


@dataclass
class Summary:
    """What a batch did.

    Attributes
    ----------
    tasks : int
        Tasks planned (inputs x targets).
    ran, skipped : int
        Run now; skipped by ``resume`` (their entries matched).
    failed : int
        Tasks whose entry says failed, of those that ran now.
    seconds : float
    outdir, report, manifest : Path
    entries : list[dict]
        The manifest entries of the planned tasks.
    """

    job: str
    tasks: int
    ran: int
    skipped: int
    failed: int
    seconds: float
    outdir: Path
    report: Path
    manifest: Path
    entries: list = field(default_factory=list, repr=False)

    @property
    def exit_status(self):
        """The command's: 1 when a task failed, else 0."""
        return 1 if self.failed else 0


def outdir_path(out):
    """OUTDIR as an absolute path; ``BatchUsageError`` when it is a file or its parent is
    missing (nothing is made yet), or it is an empty name (``-o "$OUT"`` with OUT unset would
    write into the working folder)."""
    if not str(out).strip():
        raise BatchUsageError(f"-o: expected a folder for the outputs, got an empty name "
                              f"{str(out)!r}")
    out = Path(out).expanduser().absolute()
    if out.exists() and not out.is_dir():
        raise BatchUsageError(f"{out}: expected a folder for the outputs, got a file")
    if not out.exists() and not out.parent.is_dir():
        raise BatchUsageError(f"{out}: expected an existing folder to make it in, got none "
                              f"at {out.parent}")
    return out


def prepare_outdir(out):
    """OUTDIR made (its parent must exist) and checked writable; ``BatchUsageError``
    otherwise, before any task runs."""
    out = outdir_path(out)
    try:
        out.mkdir(exist_ok=True)
    except OSError as exc:
        raise BatchUsageError(f"{out}: cannot make the folder: {exc.strerror or exc}") from None
    try:
        probe = out / f".rigedit-batch-writable-{os.getpid()}"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise BatchUsageError(f"{out}: cannot write into it: {exc.strerror or exc}") from None
    # the batch's own names taken by something else: every entry or preview would fail to
    # be written, or the report and the index at the very end
    for name, folder in ((MANIFEST_DIR, True), (THUMBS_DIR, True), ("manifest.json", False),
                         ("report.html", False)):
        there = out / name
        if there.exists() and there.is_dir() != folder:
            raise BatchUsageError(f"{there}: expected {'a folder' if folder else 'a file'} "
                                  f"of the batch's own here, got "
                                  f"{'a file' if folder else 'a folder'}")
    return out


def _lost_entry(task, exc):
    """The entry of a task whose worker died once more than the scheduler retries."""
    return {"task": task["id"], "job": task["job"], "input": task["input"],
            "target": task["target"], "inputs": {}, "settings": task["settings"],
            "rigedit": rigedit_version(), "outputs": task["outputs"], "thumbnail": None,
            "status": "failed", "failure": LOST,
            "error": f"its worker died (killed or out of memory) on every try: {one_line(exc)}",
            "quality": {}, "unsure": [], "warnings": [], "seconds": None, "worker": None}


def remove_temps(outdir, tasks):
    """Delete the temporary files and folders (``.NAME.*`` beside each output and thumbnail)
    that writers killed mid-write left (their workers died or were stopped). Only call when no
    task is running.

    Each folder is listed once (a glob per output listed OUTDIR once per task: 31 s for
    4,000 tasks), and names are compared as text, not as patterns (an output ``*.glb``
    matched every hidden file). A planned output is never litter, even a hidden one.
    """
    names = {}   # folder -> the names of the outputs in it
    for task in tasks:
        for rel in task["outputs"] + ([task["thumbnail"]] if task["thumbnail"] else []):
            path = Path(outdir) / rel
            names.setdefault(path.parent, set()).add(path.name)
    removed = []
    for folder, mine in names.items():
        try:
            listing = list(os.scandir(folder))
        except OSError:
            continue
        for entry in listing:
            if entry.name in mine or not _litter_of(entry.name, mine):
                continue
            with contextlib.suppress(OSError):
                if entry.is_dir(follow_symlinks=False):
                    shutil.rmtree(entry.path, ignore_errors=True)
                else:
                    os.unlink(entry.path)
                removed.append(Path(entry.path))
    return removed


def _litter_of(name, outputs):
    """Whether ``name`` is ``.OUTPUT.something`` for one of ``outputs``."""
    if not name.startswith("."):
        return False
    dot = name.find(".", 1)
    while dot != -1:
        if name[1:dot] in outputs:
            return True
        dot = name.find(".", dot + 1)
    return False


def run(job, inputs, out, workers=None, scheduler=None, resume=False, quiet=True,
        timeout=5.0, **job_options):
    """Run ``job`` on every input, each task writing into ``out``; the summary.

    Parameters
    ----------
    job : {"autorig", "retarget", "render", "convert", "compress"}
    inputs : list of str
        Files, folders (searched for what the job reads), globs.
    out : str or Path
        OUTDIR (made when missing; its parent must exist); every worker must see it.
    workers : int, optional
        Local worker processes (default: one per core).
    scheduler : str, optional
        ``tcp://HOST:PORT`` of a running Dask scheduler instead of a local cluster.
    resume : bool
        Skip the tasks whose manifest entry matches (succeeded, same input contents,
        settings, target and rigedit version, outputs present).
    quiet : bool
        No progress on stderr (the command shows it).
    timeout : float
        Seconds for a scheduler to answer.
    **job_options
        The job's options (:data:`rigedit.batch.tasks.JOBS`), e.g. ``template="humanoid"``
        for autorig, ``to=["humanoid"]`` for retarget, ``clip="walk"`` for render,
        ``to="glb"`` for convert, and ``thumbnails=False`` for any.

    Returns
    -------
    Summary

    Raises
    ------
    BatchUsageError
        Bad input found before any task ran (an option, an input, OUTDIR, the scheduler).
    """
    t0 = time.perf_counter()
    settings = check_options(job, job_options)
    outdir = outdir_path(out)
    skipped = []
    sources = expand_inputs(job, inputs, outdir, skipped)
    for folder, why in skipped:   # lost+found at the top of a volume, say: said, not fatal
        warnings.warn(f"{folder}: cannot read this folder ({why}); its files are left out",
                      stacklevel=2)
    say = (lambda line: None) if quiet else (lambda line: print(f"rigedit: batch: {line}",
                                                                 file=sys.stderr))
    warm = ("rigedit.batch.jobs",) + (("rigedit.render.recorder",) if settings["thumbnails"]
                                      or job == "render" else ())
    engine = Engine(workers, scheduler, timeout=timeout, say=say, warm=warm)  # checks options
    tasks = plan(job, sources, outdir, settings)
    manifest = Manifest(outdir)
    version = rigedit_version()
    todo = [t for t in tasks if not (resume and manifest.done(t, version))]
    failed = 0
    finished = set()   # ids of the tasks of ``todo`` that ended in this run
    made = not outdir.exists()
    prepare_outdir(outdir)   # cannot be made or written: said before a cluster starts
    if todo:
        try:
            engine.start(tasks=len(todo))
        except BaseException:   # a scheduler that does not answer: leave no trace
            if made:
                with contextlib.suppress(OSError):
                    outdir.rmdir()
            raise
    try:
        if todo:
            failed = _run_tasks(engine, outdir, manifest, todo, quiet, finished)
    finally:   # also when interrupted: the index and the report show what is done
        engine.close()
        remove_temps(outdir, todo)
        if outdir.is_dir():
            # a task to redo that did not end (interrupted) is "not run", not its old entry's
            # row: that one is of the input or settings before
            stale = {t["id"] for t in todo} - finished
            entries = [e for e in (manifest.read(t["id"]) for t in tasks if t["id"] not in stale)
                       if e is not None]
            manifest.write_index(job)
            report = write_report(outdir, job, entries, tasks=len(tasks))
    return Summary(job, len(tasks), len(todo), len(tasks) - len(todo), failed,
                   time.perf_counter() - t0, outdir, report, outdir / "manifest.json", entries)


def _run_tasks(engine, outdir, manifest, todo, quiet, finished):
    """Run ``todo`` on ``engine``, writing each entry as its task ends (its id added to the
    set ``finished``); the failed count."""
    failed = 0
    bar = BatchProgress(len(todo), quiet=quiet)
    try:
        engine.check_outdir(outdir)
        for task, entry, exc in engine.map(run_task, todo):
            entry = entry if exc is None else _lost_entry(task, exc)
            manifest.write(entry)
            finished.add(task["id"])
            failed += entry["status"] != "ok"
            bar.update(entry)
    finally:
        bar.close()
    return failed
