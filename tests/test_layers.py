"""The pure layers never import Qt, VTK or pyvista (docs/architecture.md, layers)."""
import subprocess
import sys

GUI = ("PyQt5", "pyvista", "pyvistaqt", "vtk", "vtkmodules", "qtpy")


def test_pure_packages_import_no_gui_modules():
    code = ("import sys, rigedit, rigedit.model, rigedit.animation, rigedit.io, rigedit.rig, "
            "rigedit.cli, rigedit.undo, rigedit.recovery\n"
            "import importlib.util\n"
            "if importlib.util.find_spec('rigedit.document'): import rigedit.document\n"
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
