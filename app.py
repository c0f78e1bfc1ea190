#!/usr/bin/env python3
"""Open the rig editor: ``python app.py [RIG]`` (RIG: a rig folder or a bundled name).

``python app.py --screenshot OUT.png [RIG]`` shows the window, renders it once, saves a picture
of the whole window and exits.
"""
from __future__ import annotations

import argparse
import os
import sys


def main(argv=None):
    parser = argparse.ArgumentParser(prog="app.py", description="rigedit, a rig editor")
    parser.add_argument("rig", nargs="?", help="rig folder or bundled name (default: quadruped)")
    parser.add_argument("--screenshot", metavar="OUT.png", help="save a window screenshot and exit")
    parser.add_argument("--size", default="1440x900", help="window size WxH (default 1440x900)")
    args = parser.parse_args(argv)

    # One BLAS thread: on a 2-core machine a second one only fights the UI (docs/architecture.md).
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    from threadpoolctl import threadpool_limits

    threadpool_limits(1)

    from PyQt5 import QtCore, QtWidgets

    QtCore.QCoreApplication.setAttribute(QtCore.Qt.AA_ShareOpenGLContexts)
    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication(sys.argv[:1])
    app.setApplicationName("rigedit")
    app.setStyle("Fusion")

    import rigedit
    from rigedit.ui import MainWindow
    from rigedit.ui.style import apply_dark_palette

    apply_dark_palette(app)
    rig = None
    if args.rig is not None:
        try:
            rig = rigedit.load_rig(args.rig)
        except (ValueError, OSError) as exc:
            print(f"app.py: {exc}", file=sys.stderr)
            return 2
    window = MainWindow(rig)
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
    # Crash safety (rigedit.ui.autosave): a hard crash's stack goes to the log, a
    # termination signal writes the recovery snapshot, and work left by an editor that is no
    # longer running is offered once the window is up.
    from rigedit.ui import autosave, errors_hook

    errors_hook.enable_faulthandler()
    notifier = autosave.install_signal_handlers(app, window)  # noqa: F841 - keep it alive
    QtCore.QTimer.singleShot(0, lambda: autosave.offer_recovery(window))
    # The compiled skinning kernels load (from numba's disk cache) in the background once the
    # window is up, so they neither delay the first frame nor get compiled during a drag.
    from rigedit.model import skinning_kernels

    QtCore.QTimer.singleShot(500, skinning_kernels.start_loading)
    window.confirm_close = True  # Save / Discard / Cancel when closing with unsaved changes
    return app.exec_()


if __name__ == "__main__":
    sys.exit(main())
