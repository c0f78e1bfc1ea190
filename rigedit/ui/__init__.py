"""The editor's Qt user interface (PyQt5 + pyvistaqt)."""
from .main_window import MainWindow, default_rig

__all__ = ["MainWindow", "default_rig"]
