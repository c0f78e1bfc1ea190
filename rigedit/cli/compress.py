"""``rigedit compress``: a rig's clips compressed with a guaranteed error (issue 20), written
as compact glTF (optionally meshopt), a rig folder or rigedit's compressed clip file; and
the options ``rigedit export --compress`` shares.

Every option is checked before the rig is read (``--max-error`` and ``--shell`` positive
finite centimetres, ``--meshopt`` only for a glTF OUT), a clip name before any compression:
one line, exit 2, nothing written.
"""
from __future__ import annotations

import math
from pathlib import Path

from .common import UsageError, load, scale_option

__all__ = ["add_parser", "cmd_compress", "compression_options", "check_compression",
           "compress_and_write", "clip_names", "DEFAULT_MAX_ERROR_CM", "DEFAULT_SHELL_CM"]

#: The issue's glTF target: 0.01 cm on a 3 cm shell (ACL's metric).
DEFAULT_MAX_ERROR_CM = 0.01
DEFAULT_SHELL_CM = 3.0
#: More than this is a typo rather than a tolerance (1 m).
LARGEST_CM = 100.0
GLTF_SUFFIXES = (".glb", ".gltf")


def compression_options(s, flag=None):
    """``--max-error``, ``--shell`` and ``--meshopt`` on parser ``s`` (``flag``: the switch
    that turns compression on, ``export``'s ``--compress``)."""
    if flag:
        s.add_argument(flag, action="store_true",
                       help="compress the clips (guaranteed error, see --max-error); glTF "
                            "or a rig folder")
    s.add_argument("--max-error", type=float, default=None, metavar="CM",
                   help=f"largest virtual-vertex error in cm on any frame (default "
                        f"{DEFAULT_MAX_ERROR_CM:g})")
    s.add_argument("--shell", type=float, default=None, metavar="CM",
                   help=f"distance of the virtual vertices from each joint in cm (default "
                        f"{DEFAULT_SHELL_CM:g}, ACL's)")
    s.add_argument("--skin-shell", action="store_true",
                   help="take each joint's virtual-vertex distance from the rig's skin (its "
                        "farthest weighted vertex) instead of --shell; the rig needs a mesh")
    s.add_argument("--meshopt", action="store_true",
                   help="also compress a glTF OUT's buffers with EXT_meshopt_compression "
                        "(required by the file; needs the meshopt package)")


def _centimetres(name, value, default):
    if value is None:
        return default
    if not (math.isfinite(value) and 0 < value <= LARGEST_CM):
        raise UsageError(f"--{name}: expected a positive number of centimetres up to "
                         f"{LARGEST_CM:g}, got {value:g}")
    return value


def check_compression(args, output):
    """``UsageError`` for a bad compression option; sets ``args.max_error_m`` and
    ``args.shell_m`` (metres)."""
    args.max_error_m = _centimetres("max-error", args.max_error, DEFAULT_MAX_ERROR_CM) / 100
    args.shell_m = _centimetres("shell", args.shell, DEFAULT_SHELL_CM) / 100
    for name, metres, cm in (("max-error", args.max_error_m, args.max_error),
                             ("shell", args.shell_m, args.shell)):
        if metres <= 0:   # 5e-324 cm is positive; in metres it is 0
            raise UsageError(f"--{name}: expected a positive number of centimetres up to "
                             f"{LARGEST_CM:g}, got {cm:g} (0 in metres)")
    if args.meshopt:
        if Path(output).suffix.lower() not in GLTF_SUFFIXES:
            raise UsageError(f"--meshopt: expected a .glb or .gltf OUT, got {output}")
        from ..io.gltf_write_compact import meshopt_available

        if not meshopt_available():
            raise UsageError("--meshopt: needs the meshopt package (pip install "
                             "'rigedit[meshopt]')")


def clip_names(rig, wanted):
    names = list(rig.clips) if not wanted else list(dict.fromkeys(wanted))
    unknown = [n for n in names if n not in rig.clips]
    if unknown:
        raise UsageError(f"{rig.path}: unknown clip {unknown[0]!r}; clips: "
                         f"{', '.join(sorted(rig.clips)) or 'none'}")
    if not names:
        raise UsageError(f"{rig.path}: the rig has no clip to compress")
    return names


def compress_and_write(rig, names, output, args):
    """Compress the clips ``names`` of ``rig`` and write ``output``: compact glTF for
    .glb/.gltf (the bound checked on the file as read, :mod:`rigedit.io.gltf_compress`);
    rigedit's own compressed clips (:mod:`rigedit.io.compressed_file`) for an .rgc file or a
    rig folder (``animations/NAME.rgc`` beside the mesh and skeleton). Returns the report's
    lines."""
    bound = dict(max_error=args.max_error_m, shell=args.shell_m)
    if getattr(args, "skin_shell", False):
        if len(rig.vertices) == 0:
            raise UsageError(f"{rig.path}: --skin-shell needs a rig with a mesh; this one has "
                             "only a skeleton (use --shell)")
        bound["mesh"] = (rig.vertices, rig.binding.indices, rig.binding.weights)
    if Path(output).suffix.lower() in GLTF_SUFFIXES:
        from ..io.gltf_compress import save_gltf_compressed_rig

        report = save_gltf_compressed_rig(rig, output, names, meshopt=args.meshopt, **bound)
        return list(report.lines())
    import dataclasses

    import rigedit
    from ..compression import compress_clips
    from ..io.compressed_file import SUFFIX, save_compressed

    from ..errors import RigFileError

    try:
        result = compress_clips(rig.skeleton, {n: rig.clips[n] for n in names},
                                target="rigedit", **bound)
    except ValueError as exc:   # a bound no encoding reaches: named like the glTF output's
        raise RigFileError(output, str(exc)) from None
    if Path(output).suffix.lower() == SUFFIX:
        save_compressed(output, rig.skeleton, result.clips)
    else:
        rigedit.save_rig(dataclasses.replace(rig.data(), clips=result.clips), output)
    return list(result.report.lines())


def add_parser(sub):
    """``rigedit compress``'s options."""
    s = sub.add_parser("compress", help="compress a rig's clips with a guaranteed error into "
                                        "glTF, a rig folder or a compressed clip file")
    s.add_argument("rig")
    s.add_argument("--clip", action="append", default=None, metavar="NAME",
                   help="a clip to compress (repeat for several; default all)")
    compression_options(s)
    s.add_argument("-o", "--output", required=True, metavar="OUT.glb|OUT.gltf|FOLDER|OUT.rgc")
    scale_option(s)
    s.set_defaults(func=cmd_compress, folder_output=True)


def cmd_compress(args):
    check_compression(args, args.output)
    rig = load(args.rig, scale=args.scale)
    names = clip_names(rig, args.clip)
    from .output import warning_lines

    with warning_lines():   # a clip written with float32 rotations: one line
        lines = compress_and_write(rig, names, args.output, args)
    for line in lines:
        print(line)
    print(f"wrote {Path(args.output).resolve()}: clips: {' '.join(names)}")
    return 0
