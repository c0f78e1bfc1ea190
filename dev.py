#!/usr/bin/env python3
"""Set up and run rigedit on a fresh machine: ``python3 dev.py run`` or ``python3 dev.py test``.

Needs only Python 3.10+. Creates ``.venv``, installs the package (editable, with the test
extra for ``test``), installs the Debian packages that Qt under Xvfb and VTK need when they are
missing (as root, or through sudo), then runs the editor or the test suite. Extra arguments go
to the editor or to pytest.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parent
VENV = ROOT / ".venv"
PY = VENV / "bin" / "python"

# What Qt's xcb plugin, VTK's OpenGL and Xvfb load on Debian 12.
DEBIAN_PACKAGES = [
    "xvfb", "xauth", "libgl1", "libegl1", "libglx-mesa0", "libgl1-mesa-dri",
    "libxkbcommon-x11-0", "libxcb-icccm4", "libxcb-image0", "libxcb-keysyms1",
    "libxcb-randr0", "libxcb-render-util0", "libxcb-xinerama0", "libxcb-xfixes0",
    "libxcb-shape0", "libxcb-cursor0", "libxcb-xkb1", "libxrender1", "libxext6", "libsm6",
    "libice6", "libfontconfig1", "libdbus-1-3", "libxt6",
    "libsuitesparse-dev",  # CHOLMOD for the heat weights' solver (scikit-sparse builds on it)
    "chromium",  # headless browser: the batch report's tests load report.html in it
]


def say(msg):
    print(f"[dev] {msg}", flush=True)


def missing_debian_packages():
    if not shutil.which("dpkg-query"):
        return []
    out = subprocess.run(["dpkg-query", "-W", "-f=${Package} ${Status}\\n", *DEBIAN_PACKAGES],
                         capture_output=True, text=True).stdout
    installed = {line.split()[0] for line in out.splitlines() if line.endswith("installed")}
    return [p for p in DEBIAN_PACKAGES if p not in installed]


def ensure_debian_packages():
    missing = missing_debian_packages()
    if not missing:
        return
    if not shutil.which("apt-get"):
        say(f"not a Debian system; please install the equivalents of: {' '.join(missing)}")
        return
    prefix = [] if os.geteuid() == 0 else (["sudo"] if shutil.which("sudo") else None)
    if prefix is None:
        say(f"missing system packages and not root: apt-get install {' '.join(missing)}")
        return
    say(f"installing system packages: {' '.join(missing)}")
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    subprocess.run(prefix + ["apt-get", "update", "-qq"], check=True, env=env)
    subprocess.run(prefix + ["apt-get", "install", "-y", "-qq", "--no-install-recommends",
                             *missing], check=True, env=env)


def ensure_venv(extra):
    if not PY.exists():
        say(f"creating {VENV}")
        try:
            venv.EnvBuilder(with_pip=True).create(VENV)
        except Exception as exc:  # Debian's python3 without python3-venv
            sys.exit(f"[dev] cannot create a virtual environment ({exc}); "
                     "on Debian: apt-get install python3-venv")
    stamp = VENV / f".installed-{extra or 'base'}"
    setup_mtime = max((ROOT / f).stat().st_mtime
                      for f in ("setup.py", "setup.cfg", "pyproject.toml"))
    if stamp.exists() and stamp.stat().st_mtime >= setup_mtime:
        return
    say("installing rigedit and its dependencies into .venv")
    subprocess.run([str(PY), "-m", "pip", "install", "-q", "--upgrade", "pip"], check=True)
    target = f".[{extra}]" if extra else "."
    subprocess.run([str(PY), "-m", "pip", "install", "-q", "-e", target], check=True, cwd=ROOT)
    # Compile the skinning kernels now, once: numba caches them on disk, so the editor never
    # compiles them itself (without the cache it would use numpy until a background compile
    # ends). A failure only means the numpy path.
    say("compiling the skinning kernels (once; cached on disk)")
    subprocess.run([str(PY), "-c", "from rigedit.model import skinning_kernels as k; k.load()"],
                   cwd=ROOT)
    # CHOLMOD makes the heat weights' solve several times faster; it builds against the
    # system's SuiteSparse, so it is a separate step whose failure leaves SciPy's SuperLU.
    if subprocess.run([str(PY), "-m", "pip", "install", "-q", "-e", ".[fast]"],
                      cwd=ROOT).returncode != 0:
        say("scikit-sparse did not install: heat weights use SciPy's SuperLU (slower)")
    subprocess.run([str(PY), "-c", "from rigedit.binding import visibility as v; v.warm()"],
                   cwd=ROOT)
    stamp.touch()


def gltf_validator_env():
    """Environment that lets the tests run the Khronos glTF Validator (npm package
    ``gltf-validator``) on every export, installed once into ``.venv/node`` where Node.js and
    npm exist; an empty dict (those tests skip, the structural checks still run) otherwise."""
    node_dir = VENV / "node"
    module = node_dir / "node_modules" / "gltf-validator"
    if not module.is_dir() and shutil.which("npm") and shutil.which("node"):
        say("installing the Khronos glTF Validator (npm gltf-validator) into .venv/node")
        try:
            subprocess.run(["npm", "install", "--silent", "--no-audit", "--no-fund", "--prefix",
                            str(node_dir), "gltf-validator"], check=False, timeout=300,
                           stdout=subprocess.DEVNULL)
        except (OSError, subprocess.TimeoutExpired) as exc:
            say(f"glTF Validator not installed ({exc}); its tests will skip")
    if not module.is_dir() or not shutil.which("node"):
        return {}
    return {"RIGEDIT_GLTF_VALIDATOR": str(ROOT / "tests" / "gltf_validator.js"),
            "NODE_PATH": str(node_dir / "node_modules")}


def main(argv):
    if not argv or argv[0] not in ("run", "test", "setup"):
        sys.exit("usage: python3 dev.py run [RIG] | test [PYTEST ARGS] | setup")
    cmd, rest = argv[0], argv[1:]
    ensure_debian_packages()
    ensure_venv("test" if cmd in ("test", "setup") else None)
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    if cmd == "setup":
        return 0
    if cmd == "test":
        env.update(gltf_validator_env())
        # The layer contracts (.importlinter) first: an import against the architecture's
        # arrows fails the run before any test does.
        say("checking the layer contracts (lint-imports)")
        if subprocess.run([str(VENV / "bin" / "lint-imports"), "--no-cache"], cwd=ROOT,
                          env=env).returncode != 0:
            say("an import breaks a layer contract (see above and docs/architecture.md)")
            return 1
        say("running the tests")
        return subprocess.run([str(PY), "-m", "pytest", *rest], cwd=ROOT, env=env).returncode
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        # No screen (a server, CI): show what the editor would, as a screenshot taken on a
        # virtual display, and a video of the default walk, and say where they are.
        out = ROOT / "out"
        out.mkdir(exist_ok=True)
        say("no display: saving a screenshot of the editor and a video of the walk instead")
        xvfb = ["xvfb-run", "-a", "-s", "-screen 0 1600x1000x24"] if shutil.which("xvfb-run") else []
        code = subprocess.run([*xvfb, str(PY), str(ROOT / "app.py"), "--screenshot",
                               str(out / "editor.png"), *rest], cwd=ROOT, env=env).returncode
        if code == 0:
            code = subprocess.run([*xvfb, str(PY), "-m", "rigedit", "render", "walk",
                                   *(["--rig", rest[0]] if rest else []), "-o",
                                   str(out / "walk.mp4")], cwd=ROOT, env=env).returncode
        return code
    return subprocess.run([str(PY), str(ROOT / "app.py"), *rest], cwd=ROOT, env=env).returncode


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
