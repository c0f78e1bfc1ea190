"""The ``rigedit`` command: headless jobs on rigs (info, list, weights, render, export,
retarget, autorig).

Bad input (a missing or malformed file, an unknown clip or joint) prints one line naming the
file and the problem and exits with status 2; no traceback. An output in a folder that does
not exist is bad input, found before any work. Ctrl-C or SIGTERM removes the output's
temporary file, prints one line and exits with 130 or 143 (see :mod:`rigedit.cli.output`).
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from .common import LOAD_OPTIONS, UsageError, load, parse_size, scale_option

__all__ = ["main", "build_parser"]

EXIT_BAD_INPUT = 2

# the shared pieces under their old names (tests and the subcommand modules use them)
_LOAD_OPTIONS = LOAD_OPTIONS
_load = load
_parse_size = parse_size
_scale_option = scale_option


def cmd_info(args):
    rig = _load(args.rig, scale=args.scale)
    sk = rig.skeleton
    lo, hi = rig.bounds()
    rows = [("name", rig.name), ("path", rig.path), ("vertices", len(rig.vertices)),
            ("faces", len(rig.faces)), ("joints", len(sk)), ("bones", rig.num_bones),
            ("max_influences", rig.binding.indices.shape[1]),
            ("weights", f"computed ({rig.weights_method})" if rig.weights_computed
             else "from file"),
            ("up", rig.up), ("bounds_min", " ".join(f"{v:.4g}" for v in lo)),
            ("bounds_max", " ".join(f"{v:.4g}" for v in hi)),
            ("clips", " ".join(sorted(rig.clips)) or "-"),
            ("shapes", " ".join(rig.morphs.names) if rig.morphs is not None else "-")]
    rows += sorted(rig.meta.notes.items())  # what a reader decided: units, frames
    for key, value in rows:
        print(f"{key}: {value}")
    return 0


def cmd_list(args):
    rig = _load(args.rig, scale=args.scale)
    for name in sorted(rig.clips):
        clip = rig.clips[name]
        print(f"{name}\t{clip.duration:.3f}s\t{'loop' if clip.loop else 'once'}")
    return 0


def cmd_weights(args):
    from .output import warning_lines
    from ..io.weights_npz import save_weights
    from ..binding.weights import compute_weights, default_method

    if not str(args.output).endswith(".npz"):
        raise UsageError(f"{args.output}: expected an output file name ending in .npz")
    rig = _load(args.rig, scale=args.scale)
    t0 = time.perf_counter()
    method = args.method or default_method(rig.faces)
    with warning_lines():
        res = compute_weights(rig.vertices, rig.skeleton, method, args.max_influences,
                              faces=rig.faces)
        dt = time.perf_counter() - t0
    idx, w = res
    fallback = getattr(res, "fallback", None)
    save_weights(args.output, idx, w, rig.skeleton.names)
    print(f"wrote {args.output}: {len(idx)} vertices, {idx.shape[1]} influences, "
          f"method {method}, {dt:.3f} s"
          + (f", {len(fallback)} fallback vertices" if fallback is not None else ""))
    return 0


#: Sane ranges of the numeric options: (low, high, low is allowed). Anything outside, and any
#: NaN or infinity, is one error line before the rig is even read.
OPTION_RANGES = {"fps": (0.0, 240.0, False), "duration": (0.0, 3600.0, False),
                 "angle": (-36000.0, 36000.0, True), "max_influences": (1, 8, True)}
SIZE_RANGE = (16, 7680)


def check_options(args):
    """``UsageError`` for a numeric option that is not finite or out of its range."""
    import math

    for key, (lo, hi, closed) in OPTION_RANGES.items():
        value = getattr(args, key, None)
        if value is None:
            continue
        above_low = lo <= value if closed else lo < value
        if not (math.isfinite(value) and above_low and value <= hi):
            raise UsageError(f"--{key.replace('_', '-')}: expected a number in "
                             f"{'[' if closed else '('}{lo:g}, {hi:g}], got {value:g}")
    if getattr(args, "size", None) is not None:
        w, h = _parse_size(args.size)
        if not (SIZE_RANGE[0] <= w <= SIZE_RANGE[1] and SIZE_RANGE[0] <= h <= SIZE_RANGE[1]):
            raise UsageError(f"--size: expected each side from {SIZE_RANGE[0]} to "
                             f"{SIZE_RANGE[1]} pixels, got {w}x{h}")


def cmd_retarget(args):
    from .retarget import run_retarget

    return run_retarget(args, _load)


def cmd_autorig(args):
    from .autorig import run_autorig

    return run_autorig(args)


class OneLineParser(argparse.ArgumentParser):
    """argparse's parser with its errors on one line (its own print the usage first: five
    lines for ``rigedit compress``) naming where the usage is; exit 2 as argparse does.
    Subcommand parsers are of the same class (argparse makes them so)."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser():
    """The ``rigedit`` parser: one subcommand per job, each added by its ``_add_*``."""
    p = OneLineParser(prog="rigedit", description="Rig editor for 3D characters: "
                                "headless jobs. RIG is a rig folder, a .glb/.gltf/.fbx/.bvh "
                                "file or a bundled name (quadruped, the default, or humanoid).")
    sub = p.add_subparsers(dest="command", required=True)
    _add_info(sub)
    _add_list(sub)
    _add_weights(sub)
    from . import export, render

    render.add_parser(sub)
    from . import batch; batch.add_parser(sub)  # noqa: E702  rigedit batch (issue 21)
    from . import compress; compress.add_parser(sub)  # noqa: E702  rigedit compress (issue 20)
    export.add_parser(sub)
    _add_retarget(sub)
    _add_autorig(sub)
    for s in sub.choices.values():   # every command is quiet on request
        if not any("-q" in a.option_strings for a in s._actions):
            s.add_argument("-q", "--quiet", action="store_true",
                           help="print nothing but errors")
    return p


def _add_info(sub):
    """``rigedit info``'s options."""
    s = sub.add_parser("info", help="print facts about a rig as key: value lines")
    s.add_argument("rig", nargs="?")
    _scale_option(s)
    s.set_defaults(func=cmd_info)


def _add_list(sub):
    """``rigedit list``'s options."""
    s = sub.add_parser("list", help="list a rig's clips and durations")
    s.add_argument("rig", nargs="?")
    _scale_option(s)
    s.set_defaults(func=cmd_list)


def _add_weights(sub):
    """``rigedit weights``'s options."""
    s = sub.add_parser("weights", help="compute skinning weights into a .npz file")
    s.add_argument("rig", nargs="?")
    s.add_argument("--method", default=None,
                   help="weights method: heat (bone heat, the default for a mesh with faces) "
                        "or idw (inverse distance, the default for a point cloud)")
    s.add_argument("--max-influences", type=int, default=4, metavar="K")
    s.add_argument("-o", "--output", required=True, metavar="FILE.npz")
    _scale_option(s)
    s.set_defaults(func=cmd_weights)


def _add_retarget(sub):
    """``rigedit retarget``'s options."""
    s = sub.add_parser("retarget", help="retarget a motion (BVH, glTF, rig folder) onto a rig")
    s.add_argument("motion", metavar="MOTION")
    s.add_argument("--to", required=True, metavar="RIG")
    s.add_argument("--map", default=None, metavar="MAP.json",
                   help="joint map {source joint: target joint} (default: found automatically)")
    s.add_argument("--save-map", default=None, metavar="MAP.json", help="write the map used")
    s.add_argument("--clip", default=None, metavar="NAME", help="the motion's clip to use")
    s.add_argument("--name", default=None, metavar="NEW", help="the new clip's name")
    s.add_argument("--strict", action="store_true",
                   help="fail (exit 2, nothing written) when the map leaves an arm, a leg, "
                        "the spine or the head unmapped")
    s.add_argument("-o", "--output", required=True, metavar="FOLDER|OUT.glb|CLIP.json")
    _scale_option(s)
    s.set_defaults(func=cmd_retarget, folder_output=True)


def _add_autorig(sub):
    """``rigedit autorig``'s options."""
    s = sub.add_parser("autorig", help="embed a template skeleton in a static mesh, bind it "
                                       "and give it the template's clips")
    s.add_argument("mesh", metavar="MESH", help="OBJ, PLY, STL, VTK, VTU, VTP or a .glb/.gltf's mesh")
    s.add_argument("--template", default="humanoid", metavar="humanoid|quadruped|SKELETON",
                   help="a bundled character's skeleton, or a skeleton .json, rig folder, "
                        ".glb or .bvh (its clips come along)")
    s.add_argument("--up", default=None, metavar="AXIS",
                   help="the mesh's up axis (y, z, ...; a negative one as --up=-z; default: "
                        "guessed and reported)")
    s.add_argument("--forward", default=None, metavar="AXIS",
                   help="the way the character faces (z, x, ...; a negative one as "
                        "--forward=-x; default: guessed)")
    s.add_argument("--method", default="heat", help="skin weights: heat (default) or idw")
    s.add_argument("--no-clips", action="store_true", help="do not retarget the template's clips")
    s.add_argument("--hint", action="append", default=None, metavar="JOINT=x,y,z",
                   help="pin a template joint at a point in the mesh file's coordinates "
                        "(repeatable)")
    s.add_argument("--hints", default=None, metavar="FILE.json",
                   help="pin joints from a JSON object {joint: [x, y, z]} (--hint wins)")
    s.add_argument("--strict", action="store_true",
                   help="a result that is NOT SURE (a failed check, an orientation without a "
                        "clear winner) is an error: exit 2, nothing written")
    s.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors (no progress bar)")
    s.add_argument("-o", "--output", required=True, metavar="RIG_FOLDER|OUT.glb")
    s.set_defaults(func=cmd_autorig, folder_output=True)


def _quietly(args):
    """Run the command with its report lines and warnings dropped (``-q``): errors still
    reach stderr, printed by :func:`main`."""
    import contextlib

    from .output import quiet_warnings

    with open(os.devnull, "w") as null, contextlib.redirect_stdout(null), quiet_warnings():
        return args.func(args)


def main(argv=None):
    """Entry point; returns the exit status."""
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    from .output import Interrupted, check_output, interruptible
    from ..errors import RigFileError

    parser = build_parser()
    args = parser.parse_args(argv)
    _LOAD_OPTIONS.clear()
    if getattr(args, "allow_outside_uris", False):
        _LOAD_OPTIONS["allow_outside_uris"] = True
    try:
        with interruptible():
            check_options(args)
            if getattr(args, "output", None) is not None:
                check_output(args.output, folder_ok=getattr(args, "folder_output", False))
            if getattr(args, "quiet", False):
                return _quietly(args)
            return args.func(args)
    except Interrupted as exc:
        print(f"rigedit: interrupted by {exc}", file=sys.stderr)
        return exc.exit_status
    except (RigFileError, UsageError) as exc:
        print(f"rigedit: error: {exc}", file=sys.stderr)
    except KeyError as exc:  # unknown joint
        print(f"rigedit: error: {exc.args[0] if exc.args else exc}", file=sys.stderr)
    except ValueError as exc:
        print(f"rigedit: error: {exc}", file=sys.stderr)
    except OSError as exc:
        name = getattr(exc, "filename", None)
        print(f"rigedit: error: {name + ': ' if name else ''}{exc.strerror or exc}",
              file=sys.stderr)
    except MemoryError:
        print("rigedit: error: out of memory", file=sys.stderr)
    except Exception as exc:  # a bug rather than bad input: one line; the traceback on request
        if os.environ.get("RIGEDIT_DEBUG"):
            raise
        said = " ".join(str(exc).split())[:300]
        print(f"rigedit: internal error: {type(exc).__name__}: {said} (RIGEDIT_DEBUG=1 shows "
              "the traceback)", file=sys.stderr)
        return 1
    return EXIT_BAD_INPUT


if __name__ == "__main__":
    sys.exit(main())
