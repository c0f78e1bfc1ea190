"""The editor's Qt user interface (PyQt5 + pyvistaqt).

``MainWindow`` and ``default_rig`` are imported on first use, so that :mod:`rigedit.ui.app`
can make the QApplication before VTK and pyvistaqt load.
"""
__all__ = ["MainWindow", "default_rig"]


def __getattr__(name):
    if name in __all__:
        from . import main_window

        return getattr(main_window, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
