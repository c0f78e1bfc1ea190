"""The work behind ``rigedit autorig`` (the parser entry lives in :mod:`rigedit.cli.main`)."""
from __future__ import annotations

import sys
from pathlib import Path

__all__ = ["run_autorig", "read_hints"]


def run_autorig(args):
    """Auto-rig ``args.mesh`` with ``args.template``, print the report, write ``args.output``.

    A progress bar shows on a terminal; Ctrl-C or SIGTERM stops the work between steps
    (see :mod:`rigedit.cli.output`). A result that is NOT SURE (``report.sure``) prints
    each reason as a warning line; with ``args.strict`` it is an error and nothing is
    written."""
    from .output import check_interrupted, warn, warning_lines
    from ..errors import RigFileError
    from ..rigging.autorig.pipeline import autorig

    read_hints(getattr(args, "hint", None), getattr(args, "hints", None))  # before the bar
    bar = None
    if sys.stderr.isatty() and not args.quiet:
        from tqdm import tqdm

        bar = tqdm(total=100, unit="%", desc="autorig", bar_format="{desc}: {percentage:3.0f}% "
                                                                   "{bar} {postfix}")

    def progress(fraction, stage):   # rigedit.progress's protocol
        check_interrupted()
        if bar is not None:
            bar.set_postfix_str(stage or "")
            if fraction is not None:   # None: a step that cannot tell; the bar waits
                bar.update(round(100 * fraction) - bar.n)

    with warning_lines():  # heat's fallbacks, bones outside the mesh: a line each
        try:
            rig = autorig(args.mesh, template=args.template, up=args.up, forward=args.forward,
                          weights=args.method, clips=not args.no_clips, progress=progress,
                          hints=read_hints(getattr(args, "hint", None),
                                           getattr(args, "hints", None)))
        finally:   # closed before the warnings print
            if bar is not None:
                bar.close()
    report = rig.autorig_report
    if not report.sure and getattr(args, "strict", False):
        raise RigFileError(args.mesh, "NOT SURE of the rig: " + "; ".join(report.reasons)
                           + " (nothing written; give --up/--forward or --hint, or drop "
                             "--strict)")
    for line in report.lines():
        print(line)
    for reason in report.reasons:   # after the report, where a user looks last
        warn(f"NOT SURE: {reason}")
    rig.save(args.output)
    print(f"wrote {Path(args.output).resolve()}: {len(rig.skeleton)} joints, "
          f"{len(rig.vertices)} vertices, clips: {' '.join(sorted(rig.clips)) or '-'}")
    return 0


def read_hints(pairs=None, path=None):
    """Joint hints from ``--hints FILE.json`` (``{"joint": [x, y, z]}``) and ``--hint
    JOINT=x,y,z`` options (these win), in the mesh file's coordinates.

    Parameters
    ----------
    pairs : list of str, optional
        Each ``JOINT=x,y,z``.
    path : str, optional
        A JSON object of joint name -> three numbers.

    Returns
    -------
    dict[str, (3,) float] or None
        None when neither is given.

    Raises
    ------
    RigFileError
        The file cannot be read or is not such an object (naming the joint when one entry
        is wrong).
    ValueError
        A ``--hint`` that is not ``JOINT=x,y,z`` (naming it).
    """
    import json
    import math

    from ..errors import RigFileError

    if not pairs and not path:
        return None
    out = {}
    if path:
        try:
            data = json.loads(Path(path).read_text(encoding="utf-8"))
        except OSError as exc:
            raise RigFileError(path, f"cannot read it: {exc.strerror or exc}") from None
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise RigFileError(path, f"expected JSON {{joint: [x, y, z]}}, got: {exc}") from None
        if not isinstance(data, dict):
            raise RigFileError(path, f"expected a JSON object {{joint: [x, y, z]}}, got "
                                     f"{type(data).__name__}")
        for name, value in data.items():
            ok = (isinstance(value, list) and len(value) == 3
                  and all(isinstance(c, (int, float)) and not isinstance(c, bool)
                          and math.isfinite(c) for c in value))
            if not ok:
                raise RigFileError(path, f"hint for joint {name!r}: expected [x, y, z] (three "
                                         f"finite numbers), got {value!r}")
            out[name] = [float(c) for c in value]
    for text in pairs or ():
        name, eq, rest = text.partition("=")
        try:
            point = [float(c) for c in rest.split(",")] if eq else []
        except ValueError:
            point = []
        if not name.strip() or len(point) != 3 or not all(map(math.isfinite, point)):
            raise ValueError(f"--hint {text!r}: expected JOINT=x,y,z (three finite numbers, "
                             "in the mesh file's coordinates)")
        out[name.strip()] = point
    return out
