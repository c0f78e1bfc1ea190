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
- **glTF-Transform** 4.5 ``resample`` with its defaults;
- where gltfpack's max error is below 0.01 cm, rigedit's own format once more at that
  error as its bound (the issue's "never a larger error than gltfpack's").

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

from rigedit.errors import RigFileError

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from anim_reader import (RAW_BYTES_PER_KEY, GltfAnimations, _trs_matrix,  # noqa: E402
                         virtual_vertex_error)

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
#: (label, max error in metres) of the rigedit glTF runs
RIGEDIT_RUNS = [("rigedit glTF 0.01 cm", 1e-4), ("rigedit glTF 0.05 cm", 5e-4)]


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


def skeleton_world(parents, local):
    """(F, J, 4, 4) model matrices of (F, J, 10) local rows over a parent array (this
    script's FK: rigedit's skeleton has the file's non-joint ancestors folded into its roots,
    so its model space is the file's world space)."""
    mats = _trs_matrix(local)
    out = np.empty_like(mats)
    done = np.zeros(len(parents), bool)
    while not done.all():
        for j in np.flatnonzero(~done):
            p = parents[j]
            if p < 0 or done[p]:
                out[:, j] = mats[:, j] if p < 0 else out[:, p] @ mats[:, j]
                done[j] = True
    return out


def _joint_columns(ref, skeleton):
    """Indices of the reference's skin joints in rigedit's skeleton."""
    return [skeleton.names.index(n) for n in ref.names]


# ---------------------------------------------------------------------- the three tools
def run_tool(cmd):
    t0 = time.perf_counter()
    run = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if run.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd[:2]))}: {run.stderr.strip()[:200]}")
    return time.perf_counter() - t0


def rigedit_rows(ref, source, tmp, rows):
    import rigedit
    from rigedit.io.gltf_compress import save_gltf_compressed_rig

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rig = rigedit.load_rig(source)
    for label, max_error in RIGEDIT_RUNS:
        for meshopt in (False, True):
            out = tmp / f"{source.stem}_{max_error:g}{'_meshopt' if meshopt else ''}.glb"
            label_m = label + (" meshopt" if meshopt else "")
            t0 = time.perf_counter()
            try:
                report = save_gltf_compressed_rig(rig, out, max_error=max_error, shell=SHELL,
                                                  meshopt=meshopt)
            except RigFileError as exc:   # a bound the compressor cannot reach
                rows.append((f"{label_m}: FAILED: {str(exc).split(': ', 1)[-1]}",))
                continue
            dt = time.perf_counter() - t0
            rows.append((label_m, *measure_gltf(ref, out), dt, report.max_error))
    own_format_row(ref, rig, rows)
    return rig


def own_format_row(ref, rig, rows, bounds=(1e-4, 5e-4)):
    """rigedit's own compressed clips at each bound (metres), decoded by rigedit's decoder
    (the one row the independent reader cannot read), FK and error here."""
    from rigedit.compression import compress_clips

    for max_error in bounds:
        label = f"rigedit own format {max_error * 100:.4g} cm"
        t0 = time.perf_counter()
        try:
            result = compress_clips(rig.skeleton, rig.clips, max_error=max_error, shell=SHELL,
                                    target="rigedit")
        except ValueError as exc:
            rows.append((f"{label}: FAILED: {exc}",))
            continue
        dt = time.perf_counter() - t0
        cols = _joint_columns(ref, rig.skeleton)
        frames = {name: skeleton_world(rig.skeleton.parents,
                                       clip.sample_many(ref.times[name]))[:, cols]
                  for name, clip in result.clips.items()}
        e = ref.errors(lambda a, t: frames[a])
        rows.append((label, ref.raw / result.report.compressed_bytes, float(e.max()),
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
#: Skeletons of 31, 67 and 101 joints for the decode timings.
DECODE_INPUTS = ["bvh-cmu/131_01.bvh", "threejs-characters/Xbot.glb",
                 "bvh-library/cmu-iclone/002_01.bvh"]


def decode_speed(sources):
    """Microseconds for one pose (one call) and per pose in a batch of 1,000 (one call),
    rigedit's decoder (compiled kernels, warmed up first), its first clip at 0.01 cm."""
    import rigedit
    from rigedit.compression import compress_clips

    print("\ndecode (rigedit's own format, 0.01 cm, random times):")
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
        for _ in range(3):   # the first calls compile (or load) the kernels
            clip.sample(t[0], pose)
            clip.sample_many(t)
        n = 2000
        t0 = time.perf_counter()
        for i in range(n):
            clip.sample(t[i % 1000], pose)
        one = (time.perf_counter() - t0) / n
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
    p.add_argument("--only", default=None, metavar="TEXT",
                   help="only the inputs whose path contains TEXT")
    args = p.parse_args(argv)
    tmp = args.out or Path(tempfile.mkdtemp(prefix="bench_compress_"))
    tmp.mkdir(parents=True, exist_ok=True)
    inputs = QUICK if args.quick else GLTF_INPUTS + BVH_INPUTS
    if args.only:
        inputs = [i for i in inputs if args.only in i]
    print(f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {os.cpu_count()} cores; "
          f"error: 3 cm shell, world space, every source key; ratio: raw / animation bytes")
    print(f"{'input':<40} {'tool':<28} {'ratio':>7} {'max cm':>8} {'p99 cm':>8} "
          f"{'time s':>7} {'report max cm':>13}")
    for rel in inputs:
        source = as_gltf(DATA / rel, tmp)
        ref = Reference(source)
        if not ref.times:
            continue
        rows = []
        rig = rigedit_rows(ref, source, tmp, rows)
        tool_rows(ref, source, tmp, args.tools, rows)
        pack = next((r for r in rows if r[0].startswith("gltfpack")), None)
        if pack is not None and pack[2] < 1e-4:   # the "never a larger error"
            own_format_row(ref, rig, rows, bounds=(pack[2],))
        for row in rows:
            if len(row) == 1:
                print(f"{Path(rel).name:<40} {row[0]}")
                continue
            label, ratio, emax, p99, dt, said = row
            said = "" if said is None else f"{said * 100:.4f}"
            print(f"{Path(rel).name:<40} {label:<28} {ratio:7.1f} {emax * 100:8.4f} "
                  f"{p99 * 100:8.4f} {dt:7.2f} {said:>13}")
    decode_speed([DATA / rel for rel in DECODE_INPUTS if (DATA / rel).is_file()])
    if args.out is None:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
