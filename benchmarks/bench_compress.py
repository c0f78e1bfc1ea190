"""Animation compression side by side: rigedit, gltfpack and glTF-Transform on the same inputs,
all measured with one independent reader (``benchmarks/anim_reader.py``: pygltflib, numpy and
meshoptimizer's decoder; its own sampler and FK, nothing of rigedit's).

Run: ``.venv/bin/python benchmarks/bench_compress.py [--quick] [--out FOLDER]
[--tools /tmp/npmtools]`` (install the tools once with ``npm install --prefix /tmp/npmtools
gltfpack @gltf-transform/cli``; a tool that is missing is left out of the table, said so).

For each input (the glTF characters and every other shared .glb/.gltf with clips, and the
BVH clips exported to glTF first with ``rigedit export X.bvh -o X.glb``):

- **rigedit** ``rigedit.compression.compress_clips`` at max 0.01 cm and at max 0.05 cm
  (3 cm shell), written as compact glTF (``save_gltf_compressed``), and at 0.01 cm as
  rigedit's own compressed clip file (measured through rigedit's decoder, then this
  script's FK: the one row not read by the independent reader);
- **gltfpack** 1.3 with its defaults (``gltfpack -i IN -o OUT``: 30 Hz resampling, its
  default rotation bits);
- **glTF-Transform** 4.5 ``resample`` with its defaults.

Measured per file: ratio against ACL's raw size (10 float32 per skin joint per source key)
to the bytes of the animation samplers' buffer views; max and 99th percentile of the
virtual-vertex error (3 cm shell, world space) on every source key time of every clip;
wall time of the compression (rigedit: the compressor in this process, not reading the
file; the tools: their whole run as a process, reading and writing the file, Node's start
included). Then the decode time of one pose and of a batch with rigedit's decoder on a 31-
and a 101-joint skeleton.
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from anim_reader import RAW_BYTES_PER_KEY, GltfAnimations, virtual_vertex_error  # noqa: E402

DATA = HERE.parent.parent / "shared" / "data"
SHELL = 0.03
GLTF_INPUTS = ["threejs-characters/Xbot.glb", "threejs-characters/RobotExpressive.glb",
               "khronos-gltf/CesiumMan.glb", "khronos-gltf/RiggedFigure.glb",
               "khronos-gltf/RiggedSimple.glb", "quaternius-farm-animals/Horse.gltf"]
BVH_INPUTS = ["bvh-cmu/131_01.bvh", "bvh-bandai/dataset-1_run_normal_001.bvh",
              "bvh-bandai/dataset-1_walk_normal_002.bvh"] + \
    [f"bvh-library/bandai-2/{p.name}" for p in sorted((DATA / "bvh-library/bandai-2").glob("*.bvh"))] + \
    [f"bvh-library/cmu-iclone/{p.name}" for p in sorted((DATA / "bvh-library/cmu-iclone").glob("*.bvh"))]
QUICK = ["threejs-characters/Xbot.glb", "bvh-cmu/131_01.bvh"]
#: (label, max error in metres) of the rigedit runs
RIGEDIT_RUNS = [("rigedit 0.01 cm", 1e-4), ("rigedit 0.05 cm", 5e-4)]


# ---------------------------------------------------------------------- measuring
class Reference:
    """A source file's clips: key times, joint matrices and raw size, read once."""

    def __init__(self, path):
        self.file = GltfAnimations(path)
        self.names = self.file.joint_names()
        self.rest = self.file.rest_joint_world()
        self.times = {a: self.file.key_times(a) for a in self.file.animations}
        self.world = {a: self.file.joint_world(a, t) for a, t in self.times.items()}
        self.raw = sum(RAW_BYTES_PER_KEY * len(self.names) * len(t) for t in self.times.values())

    def errors(self, world_of):
        """All (F*J) errors of the candidate whose joint matrices ``world_of(clip, times)``
        gives."""
        return np.concatenate([virtual_vertex_error(self.world[a], world_of(a, t), self.rest,
                                                    SHELL).ravel()
                               for a, t in self.times.items()])


def measure_gltf(ref, path):
    """(ratio, max error m, p99 m) of a candidate glTF file against ``ref``."""
    cand = GltfAnimations(path)
    own = cand.joint_names()
    missing = [n for n in ref.names if n not in own and n not in cand.names]
    if missing:
        raise ValueError(f"{path.name}: joints {missing[:3]} missing")
    cand.joints = [cand.joints[own.index(n)] if n in own else cand.names.index(n)
                   for n in ref.names]
    e = ref.errors(lambda a, t: cand.joint_world(a, t))
    return ref.raw / cand.animation_bytes(), float(e.max()), float(np.percentile(e, 99))


def _fk_of_local(ref, skeleton, local):
    """(F, J, 4, 4) world matrices of rigedit local rows through the reference file's tree:
    each joint's local TRS replaces its node's (so non-joint ancestors still count)."""
    f = ref.file
    rows = np.repeat(f.rest[None], len(local), axis=0)
    for j, name in enumerate(skeleton.names):
        rows[:, f.names.index(name)] = local[:, j]
    return f.world(rows)[:, [f.names.index(n) for n in ref.names]]


# ---------------------------------------------------------------------- the three tools
def run_tool(cmd):
    t0 = time.perf_counter()
    run = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if run.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd[:2]))}: {run.stderr.strip()[:200]}")
    return time.perf_counter() - t0


def rigedit_rows(ref, source, tmp, rows):
    import rigedit
    from rigedit.compression import compress_clips
    from rigedit.io.gltf_write_compact import save_gltf_compressed

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig = rigedit.load_rig(source)
    for label, max_error in RIGEDIT_RUNS:
        t0 = time.perf_counter()
        result = compress_clips(rig.skeleton, rig.clips, max_error=max_error, shell=SHELL,
                                target="gltf")
        dt = time.perf_counter() - t0
        out = tmp / f"{source.stem}_{max_error:g}.glb"
        save_gltf_compressed(rig, out, {n: c.to_clip() for n, c in result.clips.items()})
        rows.append((label, *measure_gltf(ref, out), dt, float(result.report.max_error)))
    own_format_row(ref, rig, tmp, rows)


def own_format_row(ref, rig, tmp, rows):
    """rigedit's own compressed clip file at 0.01 cm, decoded by rigedit, FK here."""
    from rigedit.compression import compress_clips

    t0 = time.perf_counter()
    result = compress_clips(rig.skeleton, rig.clips, max_error=1e-4, shell=SHELL,
                            target="rigedit")
    dt = time.perf_counter() - t0
    size = sum(c.nbytes for c in result.clips.values())
    sk = rig.skeleton
    frames = {}
    for name, clip in result.clips.items():
        t = ref.times[name]
        frames[name] = _fk_of_local(ref, sk, clip.sample_many(t))
    e = ref.errors(lambda a, t: frames[a])
    rows.append(("rigedit own format 0.01 cm", ref.raw / size, float(e.max()),
                 float(np.percentile(e, 99)), dt, float(result.report.max_error)))


def tool_rows(ref, source, tmp, tools, rows):
    bin_dir = tools / "node_modules" / ".bin"
    for label, exe, args in (("gltfpack (defaults)", "gltfpack", ["-i", "{in}", "-o", "{out}"]),
                             ("glTF-Transform resample", "gltf-transform",
                              ["resample", "{in}", "{out}"])):
        tool = bin_dir / exe
        if not tool.exists():
            print(f"  {label}: not installed under {tools}, left out")
            continue
        out = tmp / f"{source.stem}_{exe}.glb"
        dt = run_tool([str(tool)] + [a.format(**{"in": source, "out": out}) for a in args])
        rows.append((label, *measure_gltf(ref, out), dt, None))


def as_gltf(path, tmp):
    """A glTF input as it is; a BVH exported to .glb with ``rigedit export``."""
    if path.suffix.lower() != ".bvh":
        return path
    out = tmp / f"{path.stem}.glb"
    subprocess.run([str(Path(sys.executable).parent / "rigedit"), "export", str(path), "-o",
                    str(out), "-q"], check=True)
    return out


# ---------------------------------------------------------------------- decode speed
def decode_speed(sources, tmp):
    """Seconds for one pose and per pose in a batch of 1,000, rigedit's decoder."""
    import rigedit
    from rigedit.compression import compress_clips

    print("\ndecode (rigedit's own format, 0.01 cm):")
    for source in sources:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rig = rigedit.load_rig(source)
        name = next(iter(rig.clips))
        result = compress_clips(rig.skeleton, {name: rig.clips[name]}, max_error=1e-4,
                                shell=SHELL, target="rigedit")
        clip = result.clips[name]
        pose = rigedit.Pose(rig.skeleton)
        t = np.random.default_rng(0).uniform(0, rig.clips[name].duration, 1000)
        clip.sample(t[0], pose)
        n = 2000
        t0 = time.perf_counter()
        for i in range(n):
            clip.sample(t[i % 1000], pose)
        one = (time.perf_counter() - t0) / n
        clip.sample_many(t)
        t0 = time.perf_counter()
        for _ in range(20):
            clip.sample_many(t)
        batch = (time.perf_counter() - t0) / 20 / len(t)
        print(f"  {source.stem}: {len(rig.skeleton)} joints: one pose {one * 1e6:.1f} us, "
              f"batch of {len(t)}: {batch * 1e6:.2f} us a pose")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--quick", action="store_true", help="Xbot and CMU 131_01 only")
    p.add_argument("--tools", type=Path, default=Path("/tmp/npmtools"))
    p.add_argument("--out", type=Path, default=None, help="keep the outputs here")
    args = p.parse_args(argv)
    tmp = args.out or Path(tempfile.mkdtemp(prefix="bench_compress_"))
    tmp.mkdir(parents=True, exist_ok=True)
    inputs = QUICK if args.quick else GLTF_INPUTS + BVH_INPUTS
    print(f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {os.cpu_count()} cores; "
          f"error: 3 cm shell, world space, every source key; ratio: raw / animation bytes")
    print(f"{'input':<40} {'tool':<28} {'ratio':>7} {'max cm':>8} {'p99 cm':>8} "
          f"{'time s':>7} {'report max cm':>13}")
    exported = {}
    for rel in inputs:
        source = as_gltf(DATA / rel, tmp)
        exported[rel] = source
        ref = Reference(source)
        if not ref.times:
            continue
        rows = []
        try:
            rigedit_rows(ref, source, tmp, rows)
        except ImportError as exc:
            print(f"  rigedit: {exc}")
        tool_rows(ref, source, tmp, args.tools, rows)
        for label, ratio, emax, p99, dt, said in rows:
            said = "" if said is None else f"{said * 100:.4f}"
            print(f"{Path(rel).name:<40} {label:<28} {ratio:7.1f} {emax * 100:8.4f} "
                  f"{p99 * 100:8.4f} {dt:7.2f} {said:>13}")
    speed = [exported[k] for k in ("bvh-cmu/131_01.bvh", "bvh-library/cmu-iclone/002_01.bvh")
             if k in exported]
    if speed:
        try:
            decode_speed(speed, tmp)
        except ImportError as exc:
            print(f"  rigedit: {exc}")
    if args.out is None:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
