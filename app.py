#!/usr/bin/env python3
"""Open the rig editor: ``python app.py [RIG]`` (RIG: a rig folder or a bundled name).

``python app.py --screenshot OUT.png [RIG]`` shows the window, renders it once, saves a picture
of the whole window and exits. A thin wrapper of :func:`rigedit.ui.app.main` (installed as
``rigedit-editor``).
"""
import os
import sys

# One BLAS thread, set before numpy loads (rigedit.ui.app.main says why).
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def main(argv=None):
    from rigedit.ui.app import main as editor_main

    return editor_main(argv, prog="app.py")


if __name__ == "__main__":
    sys.exit(main())
