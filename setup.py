"""Packaging. The metadata, dependencies and entry points are in ``setup.cfg``; this file only
adds what ``setup.cfg`` cannot say together with ``packages = find:``: the repository's top-level
``assets/`` folder (the bundled characters) installed as the data package ``rigedit.assets``.

The asset build scripts (``assets/build.py``, ``assets/_build/``) stay out of the package.
"""
from setuptools import find_packages, setup
from setuptools.command.build_py import build_py

#: The bundled rig folders and the files each one holds (see rigedit.BUNDLED).
CHARACTERS = ("quadruped", "humanoid")
RIG_FILES = ("rig.json", "mesh.obj", "skeleton.json", "weights.npz", "animations/*.json")


class BuildPy(build_py):
    """build_py that ships only ``__init__.py`` from ``assets/`` (its build script is a tool of
    the repository, not part of the package)."""

    def find_package_modules(self, package, package_dir):
        modules = super().find_package_modules(package, package_dir)
        if package == "rigedit.assets":
            modules = [m for m in modules if m[1] == "__init__"]
        return modules


setup(
    packages=find_packages(include=["rigedit", "rigedit.*"]) + ["rigedit.assets"],
    package_dir={"rigedit.assets": "assets"},
    package_data={"rigedit.assets": [f"{c}/{f}" for c in CHARACTERS for f in RIG_FILES]},
    cmdclass={"build_py": BuildPy},
)
