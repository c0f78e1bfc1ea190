"""The work behind ``rigedit autorig`` (the parser entry lives in :mod:`rigedit.cli`)."""
from __future__ import annotations

import sys
from pathlib import Path

__all__ = ["run_autorig"]


def run_autorig(args):
    """Auto-rig ``args.mesh`` with ``args.template``, print the report, write ``args.output``.

    A progress bar shows on a terminal; Ctrl-C or SIGTERM stops the work between steps
    (see :mod:`rigedit.cli_output`)."""
    from ..cli_output import check_interrupted, warning_lines
    from .autorig import autorig

    bar = None
    if sys.stderr.isatty() and not args.quiet:
        from tqdm import tqdm

        bar = tqdm(total=100, unit="%", desc="autorig", bar_format="{desc}: {percentage:3.0f}% "
                                                                   "{bar} {postfix}")

    def progress(fraction, stage):
        check_interrupted()
        if bar is not None:
            bar.set_postfix_str(stage)
            bar.update(round(100 * fraction) - bar.n)

    with warning_lines():  # heat's fallbacks, bones outside the mesh: a line each
        try:
            rig = autorig(args.mesh, template=args.template, up=args.up, forward=args.forward,
                          weights=args.method, clips=not args.no_clips, progress=progress)
        finally:   # closed before the warnings print
            if bar is not None:
                bar.close()
    for line in rig.autorig_report.lines():
        print(line)
    rig.save(args.output)
    print(f"wrote {Path(args.output).resolve()}: {len(rig.skeleton)} joints, "
          f"{len(rig.vertices)} vertices, clips: {' '.join(sorted(rig.clips)) or '-'}")
    return 0
