"""The pure layers never import Qt, VTK or pyvista when loaded (docs/architecture.md, layers).

The static rules (which package may import which) are import-linter's contracts in
.importlinter, checked by ``lint-imports`` in the test command; these tests check what is
actually loaded at run time, which also catches an import made through importlib."""
import subprocess
import sys

GUI = ("PyQt5", "pyvista", "pyvistaqt", "vtk", "vtkmodules", "qtpy")


def test_pure_packages_import_no_gui_modules():
    # every module of the pure packages, not only their __init__: a GUI import hidden in a
    # submodule that the package does not import at once would slip past otherwise
    code = ("import sys, importlib, pkgutil, rigedit, rigedit.rig, rigedit.progress\n"
            "for pkg in ('model', 'animation', 'binding', 'io', 'embedding', 'rigging',\n"
            "            'editor', 'cli'):\n"
            "    package = importlib.import_module('rigedit.' + pkg)\n"
            "    for info in pkgutil.walk_packages(package.__path__, package.__name__ + '.'):\n"
            "        importlib.import_module(info.name)\n"
            f"bad = [m for m in sys.modules if m.split('.')[0] in {GUI!r}]\n"
            "print(','.join(sorted(bad)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == ""


def test_render_never_imports_qt():
    code = ("import sys, rigedit.render, rigedit.render.recorder, rigedit.render.gizmos\n"
            "print(','.join(m for m in sys.modules if m.split('.')[0] in ('PyQt5', 'pyvistaqt')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == ""


def test_the_editor_imports_vtk_by_module_not_the_whole_package():
    # ``import vtk`` loads every VTK module: 0.5 s of the editor's 2 s start-up (README,
    # Speed); rigedit imports the classes it uses from their ``vtkmodules`` modules
    code = ("import sys, pkgutil, importlib, rigedit, rigedit.ui, rigedit.render\n"
            "for pkg in ('render', 'ui'):\n"
            "    package = importlib.import_module('rigedit.' + pkg)\n"
            "    for info in pkgutil.iter_modules(package.__path__):\n"
            "        importlib.import_module(f'rigedit.{pkg}.{info.name}')\n"
            "print('vtk' in sys.modules, 'vtkmodules.vtkRenderingOpenGL2' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "False True"
