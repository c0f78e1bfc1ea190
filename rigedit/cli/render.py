"""``rigedit render``: a clip rendered off-screen to MP4 or GIF."""
from __future__ import annotations

import sys
import time
from pathlib import Path

from .common import UsageError, load, parse_size, scale_option

__all__ = ["add_parser", "cmd_render", "check_range", "clip_range", "MAX_SECONDS"]

#: The longest range rendered (seconds), as ``--duration``'s bound
MAX_SECONDS = 3600.0


def add_parser(sub):
    """``rigedit render``'s options."""
    s = sub.add_parser("render", help="render a clip off-screen to MP4 or GIF")
    s.add_argument("clip")
    s.add_argument("--rig")
    s.add_argument("-o", "--output", required=True, metavar="OUT.mp4|OUT.gif")
    s.add_argument("--fps", type=float, default=30.0)
    s.add_argument("--start", type=float, default=0.0, metavar="S",
                   help="clip time of the first frame in seconds (default 0)")
    s.add_argument("--end", type=float, default=None, metavar="E",
                   help="clip time to stop at, in seconds, not rendered (default: the "
                        "clip's duration); past the duration a looping clip plays again "
                        "from its start, another holds its last pose")
    s.add_argument("--duration", type=float, default=None, metavar="S",
                   help="seconds to render from --start (default: up to the clip's end); "
                        "not with --end")
    s.add_argument("--angle", type=float, default=0.0, metavar="DEG",
                   help="turn the front camera about the vertical axis")
    s.add_argument("--view", choices=("front", "side", "back", "top"), default="front")
    s.add_argument("--size", default="1280x720", metavar="WxH")
    s.add_argument("--skeleton", action="store_true", help="draw the bones too")
    s.add_argument("--skinning", choices=("lbs", "dqs"), default="lbs",
                   help="linear blend (default) or dual-quaternion skinning")
    s.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors (no progress bar)")
    scale_option(s)
    s.set_defaults(func=cmd_render)


def cmd_render(args):
    from .output import check_interrupted, deferred

    # A signal raised while VTK's extension modules initialise can leave them half made and
    # crash the interpreter's exit (SIGSEGV): the import only records it, and it is raised
    # once the import is done.
    check_range(args)   # before the rig is read: no seconds of loading for a typo
    with deferred():
        from ..render.recorder import frame_times, record_clip
    check_interrupted()
    size = parse_size(args.size)  # fps, duration and size were checked by check_options
    rig = load(args.rig, scale=args.scale)
    if args.clip not in rig.clips:
        raise UsageError(f"{rig.path}: unknown clip {args.clip!r}; clips: "
                         f"{', '.join(sorted(rig.clips)) or 'none'}")
    clip = rig.clips[args.clip]
    start, duration = clip_range(args, clip, rig.path)
    bar = None
    if sys.stderr.isatty() and not args.quiet:
        from tqdm import tqdm

        bar = tqdm(total=len(frame_times(duration, args.fps)), unit="frame",
                   desc=f"render {args.clip}")

    def progress(fraction, stage):   # rigedit.progress's protocol
        check_interrupted()
        if bar is not None and fraction is not None:
            bar.update(round(fraction * bar.total) - bar.n)

    t0 = time.perf_counter()
    try:
        with deferred():   # a signal stops the render between frames (see cli_output)
            n = record_clip(rig, clip, args.output, fps=args.fps, duration=duration, start=start,
                            size=size, angle=args.angle, view=args.view,
                            show_skeleton=args.skeleton, progress=progress,
                            skinning=args.skinning)
    finally:
        if bar is not None:
            bar.close()
    dt = time.perf_counter() - t0
    print(f"wrote {Path(args.output).resolve()}: {n} frames at {args.fps:g} fps, "
          f"{size[0]}x{size[1]}, {dt:.1f} s ({n / dt:.1f} frames/s)")
    return 0


def check_range(args):
    """``UsageError`` for a ``--start``/``--end`` that no clip can have: not finite, a start
    below 0, an end not after the start or more than :data:`MAX_SECONDS` after it, or
    ``--end`` together with ``--duration`` (two lengths for one range)."""
    import math

    start, end = args.start, args.end
    if not math.isfinite(start) or start < 0:
        raise UsageError(f"--start: expected a finite number of seconds >= 0, got {start:g}")
    if end is None:
        return
    if args.duration is not None:
        raise UsageError("--end and --duration both give the range's length: give one "
                         f"(--end {end:g} is --duration {end - start:g} from --start {start:g})")
    if not math.isfinite(end) or end <= start:
        raise UsageError(f"--end: expected a finite time after --start ({start:g} s), got "
                         f"{end:g}")
    if end - start > MAX_SECONDS:
        raise UsageError(f"--end: expected at most {MAX_SECONDS:g} s after --start, got "
                         f"{end - start:g} s")


def clip_range(args, clip, source):
    """``(start, duration)`` of the frames to render from ``clip``: from ``--start`` to
    ``--end``, or ``--duration`` seconds from ``--start``, else to the clip's end (one second
    of a clip without length). A start at or past the clip's end is a ``UsageError`` naming
    ``source``; an end past it is rendered (a looping clip wraps, another holds its last
    pose)."""
    length = clip.duration if clip.duration > 0 else 1.0
    if args.start >= length and args.start > 0:
        raise UsageError(f"{source}: --start {args.start:g} is past the end of clip "
                         f"{clip.name!r} ({clip.duration:g} s)")
    if args.end is not None:
        return args.start, args.end - args.start
    if args.duration is not None:
        return args.start, args.duration
    return args.start, length - args.start
