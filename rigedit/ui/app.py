"""The editor's start-up: ``rigedit-editor [RIG]`` (RIG: a rig folder or a bundled name), or
``python app.py [RIG]`` from a checkout.

``--screenshot OUT.png`` shows the window, renders it once, saves a picture of the whole
window and exits. Otherwise the editor runs with its crash safety (a hard crash's stack goes
to the log, a termination signal writes the recovery snapshot, work left by an editor that is
no longer running is offered) and asks about unsaved changes on close.
"""
from __future__ import annotations

import argparse
import os
import sys

__all__ = ["main", "parse_args"]


def parse_args(argv=None, prog="rigedit-editor"):
    parser = argparse.ArgumentParser(prog=prog, description="rigedit, a rig editor")
    parser.add_argument("rig", nargs="?", help="rig folder or bundled name (default: quadruped)")
    parser.add_argument("--screenshot", metavar="OUT.png",
                        help="save a window screenshot and exit")
    parser.add_argument("--size", default="1440x900", help="window size WxH (default 1440x900)")
    return parser.parse_args(argv)


def _application():
    """The QApplication (made here, before VTK loads), with the dark palette."""
    from PyQt5 import QtCore, QtWidgets

    from .style import apply_dark_palette

    QtCore.QCoreApplication.setAttribute(QtCore.Qt.AA_ShareOpenGLContexts)
    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication(sys.argv[:1])
    app.setApplicationName("rigedit")
    app.setStyle("Fusion")
    apply_dark_palette(app)
    return app


def main(argv=None, prog="rigedit-editor"):
    """Run the editor; returns the exit status (2 for a rig that cannot be read)."""
    args = parse_args(argv, prog)
    # One BLAS thread: on a 2-core machine a second one only fights the UI
    # (docs/architecture.md). app.py sets the variables before numpy loads; threadpoolctl
    # limits a BLAS already loaded (the rigedit-editor entry point imports rigedit first).
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    from threadpoolctl import threadpool_limits

    threadpool_limits(1)
    app = _application()

    from PyQt5 import QtCore

    from ..editor.files import load_rig
    from . import MainWindow

    rig = None
    if args.rig is not None:
        try:
            rig = load_rig(args.rig)
        except (ValueError, OSError) as exc:
            print(f"{prog}: {exc}", file=sys.stderr)
            return 2
    # Save / Discard / Cancel when closing with unsaved changes (not for a screenshot)
    window = MainWindow(rig, confirm_close=not args.screenshot)
    w, h = (int(v) for v in args.size.lower().split("x"))
    window.resize(w, h)
    window.show()
    if args.screenshot:
        for _ in range(5):
            app.processEvents()
        window.screenshot(args.screenshot)
        print(f"saved {args.screenshot}")
        window.close()
        return 0
    from . import autosave, errors_hook

    errors_hook.enable_faulthandler()
    notifier = autosave.install_signal_handlers(  # noqa: F841 - keep it alive
        app, window.autosave, window.keep_recovery_entry)
    QtCore.QTimer.singleShot(0, window.autosave.offer_recovery)
    # The compiled skinning kernels load (from numba's disk cache) in the background once the
    # window is up, so they neither delay the first frame nor get compiled during a drag.
    from ..editor.warm_up import start_loading_kernels

    QtCore.QTimer.singleShot(500, start_loading_kernels)
    return app.exec_()


if __name__ == "__main__":
    sys.exit(main())
