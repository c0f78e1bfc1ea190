"""Batch jobs over a whole library on Dask (issue 21): one task per input (and target), each
writing its outputs atomically and one manifest entry; a local cluster by default or a running
scheduler. Above the renderer and the editor's headless parts, below the command line.

>>> from rigedit import batch
>>> summary = batch.run("retarget", ["clips/"], "out", to=["humanoid"])   # doctest: +SKIP
>>> summary.failed, summary.report                                       # doctest: +SKIP

Modules: ``inputs`` (paths from files, folders, globs; content hashes), ``tasks`` (options
checked, one task per input), ``jobs`` (a task's work on a worker), ``manifest``, ``engine``
(Dask), ``progress``, ``report`` (report.html), ``sheets`` (contact sheets), ``runner``.
"""
from .inputs import BatchUsageError
from .runner import Summary, run

__all__ = ["run", "Summary", "BatchUsageError"]
