"""What the batch tests share: small motions made from the bundled humanoid (no shared data
needed), a broken one, and the command run in a child process."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from testpaths import REPO

RIGEDIT = [sys.executable, "-m", "rigedit"]


def make_motions(folder, count=3, clips=("walk", "wave", "idle")):
    """``count`` BVH files (the humanoid's clips, in turn) in ``folder``; their paths."""
    import rigedit

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rig = rigedit.load_rig("humanoid")
    paths = []
    for i in range(count):
        path = folder / f"m{i:03d}_{clips[i % len(clips)]}.bvh"
        if i < len(clips):
            rigedit.save_rig(rig, path, clips=[clips[i]])
        else:   # a copy of an earlier one: same bytes, its own task
            path.write_bytes(paths[i % len(clips)].read_bytes())
        paths.append(path)
    return paths


def broken_bvh(folder, name="broken.bvh"):
    path = Path(folder) / name
    path.write_text("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 zero\n")
    return path


def run_cli(*args, timeout=240, env=None):
    """``rigedit ARGS`` in a child process (its own local cluster); the CompletedProcess."""
    full_env = {**os.environ, "OMP_NUM_THREADS": "1", **(env or {})}
    return subprocess.run(RIGEDIT + [str(a) for a in args], cwd=REPO, env=full_env,
                          capture_output=True, text=True, timeout=timeout)


def litter(outdir):
    """Hidden files and folders (writers' temporaries) anywhere under ``outdir``."""
    return sorted(p for p in Path(outdir).rglob(".*"))


def free_port():
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run_in_process(root, count=2, thumbnails=False):
    """``count`` motions and a broken file retargeted onto the humanoid by
    :func:`rigedit.batch.jobs.run_task` in this process (no cluster): ``(out, tasks,
    entries)``; OUTDIR is ``root / "out"``."""
    from rigedit.batch.jobs import run_task
    from rigedit.batch.tasks import check_options, plan

    motions = make_motions(root / "in", count) + [broken_bvh(root / "in")]
    out = root / "out"
    out.mkdir()
    settings = check_options("retarget", {"to": ["humanoid"], "thumbnails": thumbnails})
    tasks = plan("retarget", motions, out, settings)
    return out, tasks, [run_task(t) for t in tasks]
