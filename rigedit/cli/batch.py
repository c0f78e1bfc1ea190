"""``rigedit batch JOB INPUTS... -o OUTDIR``: a job over a whole library on Dask (the work is
:func:`rigedit.batch.run`; see docs/batch.md).

Exit status: 0 when every task succeeded, 1 when some failed (how many is said, and each is
a row of ``OUTDIR/report.html``), 2 for bad input found before any work (an option, an input
that does not exist, an OUTDIR that cannot be written, a scheduler that does not answer).
"""
from __future__ import annotations

import argparse
import sys

__all__ = ["add_parser", "cmd_batch"]


def _common(s):
    """The options every batch job takes."""
    s.add_argument("-o", "--output", required=True, metavar="OUTDIR",
                   help="the folder for the outputs, the manifest and report.html (made when "
                        "missing; on a cluster every worker must see it at this path)")
    where = s.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=None, metavar="N",
                       help="local worker processes (default: one per core)")
    where.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT",
                       help="a running Dask scheduler instead of a local cluster")
    s.add_argument("--resume", action="store_true",
                   help="skip the tasks the manifest says succeeded with the same inputs, "
                        "settings and rigedit version")
    s.add_argument("--no-thumbnails", dest="thumbnails", action="store_false",
                   help="no animated preview per output (faster)")
    s.add_argument("--timeout", type=float, default=5.0, metavar="S",
                   help="seconds a scheduler has to answer (default 5)")
    s.add_argument("-q", "--quiet", action="store_true", default=argparse.SUPPRESS,
                   help="print nothing but errors (no progress bar)")


def add_parser(sub):
    """``rigedit batch``'s parser and its jobs."""
    s = sub.add_parser("batch", help="run a job over many files on Dask (local cores or a "
                                     "cluster), with a manifest and OUTDIR/report.html")
    s.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    jobs = s.add_subparsers(dest="job", required=True, metavar="JOB")

    j = jobs.add_parser("autorig", help="rig every mesh with a template skeleton")
    j.add_argument("inputs", nargs="+", metavar="MESHES")
    j.add_argument("--template", default="humanoid", metavar="humanoid|quadruped|SKELETON")
    j.add_argument("--up", default=None, metavar="AXIS")
    j.add_argument("--forward", default=None, metavar="AXIS")
    j.add_argument("--method", default="heat", help="skin weights: heat (default) or idw")
    j.add_argument("--no-clips", dest="clips", action="store_false",
                   help="do not retarget the template's clips")
    j.add_argument("--format", default="glb", help="glb (default) or folder")

    j = jobs.add_parser("retarget", help="every motion onto every target rig")
    j.add_argument("inputs", nargs="+", metavar="MOTIONS")
    j.add_argument("--to", action="append", required=True, metavar="RIG",
                   help="a target rig (repeat for several)")
    j.add_argument("--map", default=None, metavar="MAP.json")
    j.add_argument("--clip", default=None, metavar="NAME",
                   help="the motions' clip (default: each motion's first)")
    j.add_argument("--format", default="glb", help="glb (default) or folder")

    j = jobs.add_parser("render", help="a preview video and a contact sheet per rig")
    j.add_argument("inputs", nargs="+", metavar="RIGS")
    j.add_argument("--clip", required=True, metavar="NAME")
    j.add_argument("--fps", type=float, default=24.0)
    j.add_argument("--duration", type=float, default=None, metavar="S")
    j.add_argument("--size", default="320x240", metavar="WxH")
    j.add_argument("--view", default="front", help="front (default), side, back or top")
    j.add_argument("--video", default="mp4", help="mp4 (default) or gif")

    j = jobs.add_parser("convert", help="every rig written as .glb, .bvh or a rig folder")
    j.add_argument("inputs", nargs="+", metavar="FILES")
    j.add_argument("--to", required=True, metavar="glb|bvh|folder")
    j.add_argument("--clip", default=None, metavar="NAME", help="the clip of a .bvh output")

    j = jobs.add_parser("compress", help="every rig's clips compressed with a guaranteed "
                                         "error into a compact .glb")
    j.add_argument("inputs", nargs="+", metavar="FILES")
    j.add_argument("--max-error", type=float, required=True, metavar="CM",
                   help="largest virtual-vertex error in cm on any frame")
    j.add_argument("--shell", type=float, default=3.0, metavar="CM",
                   help="distance of the virtual vertices from each joint in cm (default 3)")

    for j in jobs.choices.values():
        _common(j)
    s.set_defaults(func=cmd_batch, folder_output=True)


#: Parsed names that are not job options.
_NOT_OPTIONS = {"command", "job", "inputs", "output", "workers", "scheduler", "resume",
                "timeout", "quiet", "func", "folder_output", "allow_outside_uris", "scale"}


def cmd_batch(args):
    """Run the batch; 1 when a task failed (saying how many), else 0."""
    from ..batch import run
    from ..batch.inputs import shown
    from .output import warning_lines

    options = {k: v for k, v in vars(args).items() if k not in _NOT_OPTIONS}
    quiet = getattr(args, "quiet", False)
    with warning_lines():   # a folder that cannot be read: one line each (none with -q)
        summary = run(args.job, args.inputs, args.output, workers=args.workers,
                      scheduler=args.scheduler, resume=args.resume, quiet=quiet,
                      timeout=args.timeout, **options)
    report = shown(str(summary.report))   # stdout takes no undecodable bytes of a name
    print(f"{summary.tasks} tasks: {summary.ran} run, {summary.skipped} skipped (done before), "
          f"{summary.failed} failed; {summary.seconds:.1f} s; report {report}")
    if summary.failed:
        print(f"rigedit: error: {summary.failed} of {summary.ran} tasks failed (their errors "
              f"are in {summary.report})", file=sys.stderr)
    return summary.exit_status
