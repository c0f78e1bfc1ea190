"""Auto-rigging meshes that are not one closed surface: the volume proxy's effect and cost.

Run: ``.venv/bin/python benchmarks/bench_autorig_open.py [--speed] [--accuracy]`` (both by
default).

**Accuracy**: CD-J2J (RigNet's, % of the bounding-box diagonal) through ``rigedit.autorig``
(own frame, orientation guessed, no clips) on the shared characters with artist skeletons
(the name tables of ``tests/test_embedding_stretch.py``), three ways: as the pipeline
decides (proxy or not), never through the proxy (the old path), and always through it; and
the synthetic meshes of ``tests/test_autorig_open_meshes.py`` (axes given): the bundled
humanoid open at the eyes with unwelded seams, and as a triangle soup (truth: its skeleton).

**Votes** (``--votes``): the same synthetic cases and the robot of 50 open boxes with the
proxy's ``min_votes`` at 7, 9, 11 and 13 of its 13 lines (CD-J2J; the robot's largest
joint error in metres against where its hands, feet, head and hips belong).

**Speed**: the bundled humanoid's mesh split once and decimated to about 50k vertices (as in
``bench_autorig.py``), opened at the eyes and seams: the proxy's seconds, and the whole
auto-rig with the axes given and guessed.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

import rigedit  # noqa: E402
import rigedit.rigging.autorig.mesh_check as mesh_check  # noqa: E402
from rigedit.embedding import cd_j2j  # noqa: E402
from test_autorig_open_meshes import _cd_to_truth, _seam, _soup, open_humanoid  # noqa: E402
from test_embedding_stretch import SHARED, shared_case  # noqa: E402


def _rig(mesh, template="humanoid", **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rigedit.autorig(mesh, template=template, clips=False, **kw)


def _shared(mode):
    """CD-J2J of each shared character with the proxy as decided / never / always."""
    real = mesh_check._proxy_reasons
    if mode == "never":
        mesh_check._proxy_reasons = lambda *a: []
    elif mode == "always":
        mesh_check._proxy_reasons = lambda *a: real(*a) or ["forced"]
    templates = {n: rigedit.load_rig(n) for n in ("humanoid", "quadruped")}
    try:
        for path, (which, table) in SHARED.items():
            v, f, _, truth = shared_case(path, templates[which])
            t0 = time.perf_counter()
            try:
                rig = _rig((v, f), which)
            except ValueError as exc:
                print(f"| {path} | {mode} | FAILED: {exc} |")
                continue
            rep = rig.autorig_report
            m = rep.transform
            sk = rig.skeleton
            got = np.array([sk.bind_matrices[sk.index[n], :3, 3] for n in table])
            diag = float(np.linalg.norm(np.ptp(rig.vertices, axis=0)))
            px = rep.checks.proxy
            print(f"| {path} | {mode} | {cd_j2j(got, truth @ m[:3, :3].T + m[:3, 3], diag):.2f}% "
                  f"| {'-' if px is None else f'{len(px.faces)} triangles, {px.seconds:.2f} s'} "
                  f"| {time.perf_counter() - t0:.1f} s |", flush=True)
    finally:
        mesh_check._proxy_reasons = real


#: The humanoid template's joints -> RobotExpressive's (by anatomy; its hands' middle palm
#: bone as the hand; Spine1 has no counterpart).
ROBOT = {"Hips": "Hips", "Spine": "Abdomen", "Spine2": "Torso", "Neck": "Neck", "Head": "Head"}
for _s, _t in (("Left", "L"), ("Right", "R")):
    ROBOT.update({f"{_s}Shoulder": f"Shoulder.{_t}", f"{_s}Arm": f"UpperArm.{_t}",
                  f"{_s}ForeArm": f"LowerArm.{_t}", f"{_s}Hand": f"Palm2.{_t}",
                  f"{_s}UpLeg": f"UpperLeg.{_t}", f"{_s}Leg": f"LowerLeg.{_t}",
                  f"{_s}Foot": f"Foot.{_t}"})


def robot():
    """RobotExpressive read whole (its parts hang from bones), the humanoid template."""
    from test_embedding import DATA

    path = DATA / "threejs-characters" / "RobotExpressive.glb"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        art = rigedit.load_rig(str(path))
    truth = art.joint_matrices(art.rest_pose())[[art.skeleton.index[n]
                                                 for n in ROBOT.values()], :3, 3]
    t0 = time.perf_counter()
    rig = _rig(path)
    rep = rig.autorig_report
    m = rep.transform
    sk = rig.skeleton
    got = np.array([sk.bind_matrices[sk.index[n], :3, 3] for n in ROBOT])
    diag = float(np.linalg.norm(np.ptp(rig.vertices, axis=0)))
    sure = getattr(rep, "sure", None)
    print(f"RobotExpressive: {len(rig.vertices)} vertices, CD-J2J "
          f"{cd_j2j(got, truth @ m[:3, :3].T + m[:3, 3], diag):.2f}% ({len(ROBOT)} joints), "
          f"{rep.orientation.describe()}, sure: {sure}, {time.perf_counter() - t0:.1f} s",
          flush=True)


def accuracy():
    robot()
    print("## CD-J2J, shared characters (orientation guessed)")
    print("| mesh | proxy | CD-J2J | proxy built | autorig |")
    print("|---|---|---|---|---|")
    for mode in ("as decided", "never", "always"):
        _shared(mode)
    h = rigedit.load_rig("humanoid")
    names = list(h.skeleton.names[1:])
    rng = np.random.default_rng(3)
    tris = h.vertices[h.faces] + rng.normal(scale=2e-4, size=(len(h.faces), 3, 3))
    print("## CD-J2J, synthetic (axes given; truth: the bundled skeleton)")
    for label, mesh in (("closed", (h.vertices, h.faces)), ("open eyes and seams",
                                                             open_humanoid(h)),
                        ("triangle soup", _soup(tris))):
        rig = _rig(mesh, up="y", forward="z")
        print(f"{label}: {_cd_to_truth(rig, h.skeleton, names):.2f}%", flush=True)


def votes():
    import rigedit.embedding.volume as volume
    from test_autorig_open_meshes import _joints_rig, _to_rig, robot

    h = rigedit.load_rig("humanoid")
    names = list(h.skeleton.names[1:])
    rng = np.random.default_rng(3)
    soup = _soup(h.vertices[h.faces] + rng.normal(scale=2e-4, size=(len(h.faces), 3, 3)))
    rv, rf, rj = robot()
    defaults = volume.volume_proxy.__defaults__
    print("## min_votes (axes given)")
    try:
        for n in (7, 9, 11, 13):
            d = list(defaults)
            d[1] = n
            volume.volume_proxy.__defaults__ = tuple(d)
            out = []
            for label, mesh in (("open humanoid", open_humanoid(h)), ("soup", soup)):
                try:
                    rig = _rig(mesh, up="y", forward="z")
                    out.append(f"{label} {_cd_to_truth(rig, h.skeleton, names):.2f}%")
                except ValueError as exc:
                    out.append(f"{label} FAILED ({exc})")
            try:
                rig = _rig((rv, rf), up="y", forward="z")
                err = np.linalg.norm(_joints_rig(rig, list(rj)) - _to_rig(
                    rig, np.array(list(rj.values()))), axis=1)
                out.append(f"robot largest joint error {err.max():.3f} m")
            except ValueError as exc:
                out.append(f"robot FAILED ({exc})")
            print(f"min_votes {n}: " + "; ".join(out), flush=True)
    finally:
        volume.volume_proxy.__defaults__ = defaults


def speed():
    from bench_autorig import _fifty_k

    h = rigedit.load_rig("humanoid")
    v, f, _ = _fifty_k(h.vertices, h.faces, 1)
    for cut in (lambda c: c[:, 1] > 1.50, lambda c: (c[:, 1] < 0.98) & (c[:, 1] > 0.2),
                lambda c: np.abs(c[:, 0]) > 0.62, lambda c: c[:, 1] <= 0.2):
        v, f = _seam(v, f, cut(v[f].mean(axis=1)))
    print(f"## speed: open humanoid, {len(v)} vertices, {len(f)} triangles")
    t0 = time.perf_counter()
    c = mesh_check.check_mesh(v, f, "open")
    print(f"check_mesh {time.perf_counter() - t0:.2f} s, of which the proxy "
          f"{c.proxy.seconds:.2f} s ({len(c.proxy.faces)} triangles)", flush=True)
    for kw in ({"up": "y", "forward": "z"}, {}):
        t0 = time.perf_counter()
        rig = _rig((v, f), **kw)
        s = rig.autorig_report.seconds
        print(f"autorig ({'axes given' if kw else 'orientation guessed'}): "
              f"{time.perf_counter() - t0:.1f} s; " + ", ".join(
                  f"{k} {x:.2f}" for k, x in s.items() if not k.startswith("embedding/")),
              flush=True)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--speed", action="store_true")
    p.add_argument("--accuracy", action="store_true")
    p.add_argument("--votes", action="store_true")
    args = p.parse_args()
    print(f"load average at start: {' '.join(f'{x:.1f}' for x in os.getloadavg())} "
          f"({os.cpu_count()} cores; other jobs share the machine)")
    if args.votes:
        votes()
    both = not (args.speed or args.accuracy or args.votes)
    if args.speed or both:
        speed()
    if args.accuracy or both:
        accuracy()
    print(f"load average at end: {' '.join(f'{x:.1f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
