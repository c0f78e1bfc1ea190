"""``rigedit export``: a rig written as glTF, FBX, BVH or a rig folder."""
from __future__ import annotations

from pathlib import Path

from .common import UsageError, load, scale_option
from .compress import clip_names, compress_and_write, compression_options, check_compression

__all__ = ["add_parser", "cmd_export"]


def add_parser(sub):
    """``rigedit export``'s options."""
    s = sub.add_parser("export",
                       help="write a rig as glTF (.glb/.gltf), FBX, BVH or a rig folder")
    s.add_argument("rig")
    s.add_argument("-o", "--output", required=True,
                   metavar="OUT.glb|OUT.gltf|OUT.fbx|OUT.bvh|FOLDER")
    s.add_argument("--clip", action="append", default=None, metavar="NAME",
                   help="a clip to write (repeat for several; default all, BVH: the first)")
    s.add_argument("--fbx-units", choices=("cm", "m"), default="cm",
                   help="length unit of an .fbx OUT: cm (the default, what Unity and Unreal "
                        "import at scale 1) or m")
    compression_options(s, "--compress")
    scale_option(s)
    s.set_defaults(func=cmd_export, folder_output=True)


def cmd_export(args):
    import rigedit

    if args.compress:
        if Path(args.output).suffix.lower() in (".fbx", ".bvh"):
            raise UsageError(f"--compress: expected a .glb/.gltf OUT or a rig folder, got "
                             f"{args.output}")
        check_compression(args, args.output)
    elif args.max_error is not None or args.shell is not None or args.meshopt:
        raise UsageError("--max-error, --shell and --meshopt go with --compress")
    rig = load(args.rig, scale=args.scale)
    if args.compress:
        names = clip_names(rig, args.clip)
        from .output import warning_lines

        with warning_lines():
            lines = compress_and_write(rig, names, args.output, args)
        for line in lines:
            print(line)
        print(f"wrote {Path(args.output).resolve()}: {len(rig.skeleton)} joints, "
              f"{len(rig.vertices)} vertices, compressed clips: {' '.join(names)}")
        return 0
    if Path(args.output).suffix.lower() == ".fbx":
        from ..io.fbx_write import write_fbx

        write_fbx(rig.data(), args.output, clips=args.clip, units=args.fbx_units)
    else:
        rigedit.save_rig(rig, args.output, clips=args.clip)
    clips = args.clip or sorted(rig.clips)
    if Path(args.output).suffix.lower() == ".bvh":
        clips = clips[:1]
    print(f"wrote {Path(args.output).resolve()}: {len(rig.skeleton)} joints, "
          f"{len(rig.vertices)} vertices, clips: {' '.join(clips) or '-'}")
    return 0
