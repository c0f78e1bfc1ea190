"""Packaging: the wheel carries the bundled characters, and an installed rigedit finds them
inside the package (not in a checkout's assets/ folder).

The wheel is built offline from a copy of the sources (``pip wheel --no-build-isolation``, so
setuptools and wheel come from the running environment), then unpacked into a folder that a
subprocess puts first on ``sys.path``: for a pure-Python wheel that is what an install does.
"""
import hashlib
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SOURCES = ("setup.py", "setup.cfg", "pyproject.toml", "README.md", "rigedit", "assets")
CHARACTERS = ("quadruped", "humanoid")


def _asset_files():
    """Every file a bundled rig folder is made of, relative to assets/ (posix paths)."""
    files = []
    for name in CHARACTERS:
        folder = ROOT / "assets" / name
        for rel in ("mesh.obj", "skeleton.json", "weights.npz", "rig.json"):
            assert (folder / rel).is_file(), f"the repository lacks assets/{name}/{rel}"
            files.append(f"{name}/{rel}")
        clips = sorted((folder / "animations").glob("*.json"))
        assert clips, f"assets/{name}/animations holds no clip"
        files += [f"{name}/animations/{c.name}" for c in clips]
    return files


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    """Path of a wheel built from a copy of the repository's sources."""
    src = tmp_path_factory.mktemp("src")
    for name in SOURCES:
        path = ROOT / name
        if path.is_dir():
            shutil.copytree(path, src / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(path, src / name)
    out = tmp_path_factory.mktemp("dist")
    proc = subprocess.run([sys.executable, "-m", "pip", "wheel", str(src), "--no-deps",
                           "--no-build-isolation", "--no-index", "-q", "-w", str(out)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    (whl,) = out.glob("rigedit-*.whl")
    return whl


def test_wheel_carries_every_asset_file_unchanged(wheel):
    with zipfile.ZipFile(wheel) as zf:
        names = set(zf.namelist())
        for rel in _asset_files():
            member = f"rigedit/assets/{rel}"
            assert member in names, f"{member} missing from {wheel.name}"
            data = zf.read(member)
            assert hashlib.sha256(data).digest() == \
                hashlib.sha256((ROOT / "assets" / rel).read_bytes()).digest(), member
    # The asset build scripts are tools of the repository, not part of the package.
    assert not [n for n in names if n.startswith("rigedit/assets/_build")
                or n == "rigedit/assets/build.py"]
    assert "rigedit/__init__.py" in names and "rigedit/model/skinning.py" in names


def test_installed_package_resolves_assets_inside_itself(wheel, tmp_path):
    site = tmp_path / "site"
    with zipfile.ZipFile(wheel) as zf:
        zf.extractall(site)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    code = ("import rigedit, pathlib\n"
            "rig = rigedit.load_rig('humanoid')\n"
            "print(pathlib.Path(rigedit.__file__).parent)\n"
            "print(rigedit.ASSETS_DIR)\n"
            "print(rig.vertices.shape[0], ' '.join(sorted(rig.clips)))\n")
    env = {k: v for k, v in os.environ.items() if k != "RIGEDIT_ASSETS"}
    env["PYTHONPATH"] = str(site)
    proc = subprocess.run([sys.executable, "-c", code], cwd=elsewhere, env=env,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    package, assets, loaded = proc.stdout.strip().splitlines()
    assert Path(package) == site / "rigedit"
    assert Path(assets) == site / "rigedit" / "assets"
    clips = sorted(p.stem for p in (ROOT / "assets" / "humanoid" / "animations").glob("*.json"))
    n_vertices = sum(1 for line in (ROOT / "assets" / "humanoid" / "mesh.obj").open()
                     if line.startswith("v "))
    assert loaded == f"{n_vertices} {' '.join(clips)}"


def test_checkout_and_editable_install_resolve_the_repository_assets():
    # In this environment rigedit is the checkout (editable install or sys.path): its
    # ASSETS_DIR must be the repository's assets/ folder, through importlib.resources or not.
    env = {k: v for k, v in os.environ.items() if k != "RIGEDIT_ASSETS"}
    out = subprocess.run([sys.executable, "-c", "import rigedit; print(rigedit.ASSETS_DIR)"],
                         cwd=ROOT / "tests", env=env, capture_output=True, text=True,
                         check=True).stdout.strip()
    assert Path(out).resolve() == (ROOT / "assets").resolve()
