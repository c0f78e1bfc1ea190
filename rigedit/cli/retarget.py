"""The work behind ``rigedit retarget`` (the parser entry lives in :mod:`rigedit.cli.main`)."""
from __future__ import annotations

import sys
from pathlib import Path

from ..errors import RigFileError
from .output import warn

__all__ = ["run_retarget"]


def _pick_clip(rig, name, path):
    if name is not None:
        if name not in rig.clips:
            raise RigFileError(path, f"no clip {name!r} (clips: {', '.join(sorted(rig.clips))})")
        return rig.clips[name]
    if not rig.clips:
        raise RigFileError(path, "expected a clip to retarget, got none")
    if len(rig.clips) > 1:
        raise RigFileError(path, f"several clips ({', '.join(sorted(rig.clips))}); choose "
                           f"one with --clip")
    return next(iter(rig.clips.values()))


def run_retarget(args, load):
    """Retarget ``args.motion``'s clip onto ``args.to`` and write ``args.output``.

    ``load(path, scale=...)`` reads a rig (the CLI's loader, which prints warnings). A map
    that leaves an arm, a leg, the spine or the head of the target unmapped is a warning
    listing them; with ``args.strict`` an error (nothing is written)."""
    from .output import warning_lines
    from ..rigging.retarget.name_map import load_map, save_map, unmapped_parts
    from ..rigging.retarget.pipeline import retarget_result

    source = load(args.motion, scale=args.scale)
    target = load(args.to)
    clip = _pick_clip(source, args.clip, args.motion)
    mapping = None
    if args.map is not None:
        mapping = load_map(args.map, source.skeleton, target.skeleton)
    # a skeleton with no legs or arms is a ValueError naming the file: the CLI prints it;
    # a retarget without legs says so in a warning line
    with warning_lines():
        res = retarget_result(source, clip, target, mapping, args.name,
                              source_what=str(args.motion), target_what=str(args.to))
    print(f"map ({len(res.mapping)} joints, source -> target):")
    for s, t in res.mapping.items():
        print(f"  {s} -> {t}")
    tsk = target.skeleton
    missing = unmapped_parts(res.target_calibration, [tsk.index[t] for t in res.mapping.values()])
    if missing:
        what = (f"the joint map from {args.motion} leaves parts of the target unmapped (they "
                f"keep their rest pose): {'; '.join(missing)}")
        if args.strict:
            raise RigFileError(args.to, f"{what}; give a joint map (--map) or drop --strict")
        warn(f"{args.to}: {what}")
    print(f"calibration: source {res.source_calibration.source}, target "
          f"{res.target_calibration.source}; facing turn {res.facing_degrees:g} deg; "
          f"scale {res.scale:.3f}; contact frames {res.contact.any(axis=1).sum()} of "
          f"{len(res.times)}")
    if res.facing_note:
        print(f"rigedit: warning: {args.motion}: NOT SURE of the facing: {res.facing_note}",
              file=sys.stderr)
    tgt = res.target_calibration
    if tgt.kind == "legs":  # not two humanoids: say which legs were found
        feet = ", ".join(target.skeleton.names[j] for j in tgt.contacts)
        print(f"legs: target {len(tgt.legs)} (feet {feet}), source "
              f"{len(res.source_calibration.legs)}; hips {target.skeleton.names[tgt.hips]}")
    if args.save_map:
        save_map(args.save_map, res.mapping)
        print(f"wrote {Path(args.save_map).resolve()}")
    out = Path(args.output)
    new = res.clip
    if out.suffix.lower() == ".json":
        from ..io.clip_json import save_clip

        save_clip(out, new)
    else:
        if new.name in target.clips:
            warn(f"replacing the target's clip {new.name!r}")
        target.clips[new.name] = new
        target.save(out, clips=[new.name] if out.suffix.lower() == ".bvh" else None)
    print(f"wrote {out.resolve()}: clip {new.name!r}, {new.duration:.2f} s, "
          f"{len(res.times)} keys per track")
    return 0
