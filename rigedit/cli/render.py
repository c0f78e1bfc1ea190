"""``rigedit render``: a clip rendered off-screen to MP4 or GIF."""
from __future__ import annotations

import sys
import time
from pathlib import Path

from .common import UsageError, load, parse_size, scale_option

__all__ = ["add_parser", "cmd_render"]


def add_parser(sub):
    """``rigedit render``'s options."""
    s = sub.add_parser("render", help="render a clip off-screen to MP4 or GIF")
    s.add_argument("clip")
    s.add_argument("--rig")
    s.add_argument("-o", "--output", required=True, metavar="OUT.mp4|OUT.gif")
    s.add_argument("--fps", type=float, default=30.0)
    s.add_argument("--duration", type=float, default=None, metavar="S",
                   help="seconds to render (default: the clip's duration)")
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
    with deferred():
        from ..render.recorder import frame_times, record_clip
    check_interrupted()
    size = parse_size(args.size)  # fps, duration and size were checked by check_options
    rig = load(args.rig, scale=args.scale)
    if args.clip not in rig.clips:
        raise UsageError(f"{rig.path}: unknown clip {args.clip!r}; clips: "
                         f"{', '.join(sorted(rig.clips)) or 'none'}")
    clip = rig.clips[args.clip]
    bar = None
    if sys.stderr.isatty() and not args.quiet:
        from tqdm import tqdm

        bar = tqdm(total=len(frame_times(args.duration or clip.duration or 1.0, args.fps)),
                   unit="frame", desc=f"render {args.clip}")

    def progress(fraction, stage):   # rigedit.progress's protocol
        check_interrupted()
        if bar is not None and fraction is not None:
            bar.update(round(fraction * bar.total) - bar.n)

    t0 = time.perf_counter()
    try:
        with deferred():   # a signal stops the render between frames (see cli_output)
            n = record_clip(rig, clip, args.output, fps=args.fps, duration=args.duration,
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
