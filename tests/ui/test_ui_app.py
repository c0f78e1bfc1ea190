"""``python app.py --screenshot OUT.png`` renders the window and exits; a bad rig fails clearly."""
from testpaths import REPO
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.ui
ROOT = REPO


def test_app_screenshot(tmp_path):
    from PyQt5 import QtGui

    out = tmp_path / "editor.png"
    proc = subprocess.run([sys.executable, str(ROOT / "app.py"), "--screenshot", str(out),
                           "--size", "1000x700"], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "QT_QPA_PLATFORM": "xcb"})
    assert proc.returncode == 0, proc.stderr
    img = QtGui.QImage(str(out)).convertToFormat(QtGui.QImage.Format_RGB888)
    w, h = img.width(), img.height()
    assert w >= 1000 and h >= 700  # docks may ask for more than the requested size
    ptr = img.constBits()
    ptr.setsize(img.byteCount())
    a = np.frombuffer(ptr, np.uint8).reshape(h, img.bytesPerLine())[:, :3 * w]
    a = a.reshape(h, w, 3).astype(int)
    # The mesh (a warm beige) fills part of the left-hand 3D view, not the right-hand panels.
    beige = (a[..., 0] > a[..., 2] + 25) & (a[..., 0] > 90) & (a[..., 1] > 70)
    assert 0.025 < beige[:, : int(0.6 * w)].mean() < 0.055  # measured 0.036-0.039
    assert beige[:, int(0.85 * w):].mean() < 0.01


def test_app_bad_rig_exits_with_message(tmp_path):
    proc = subprocess.run([sys.executable, str(ROOT / "app.py"), "--screenshot",
                           str(tmp_path / "x.png"), str(tmp_path / "missing")],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    assert "missing" in proc.stderr and "Traceback" not in proc.stderr


def test_the_editor_entry_point_is_the_packages_main(tmp_path):
    # setup.cfg installs rigedit-editor = rigedit.ui.app:main; app.py is a thin wrapper of it
    import configparser

    cfg = configparser.ConfigParser()
    cfg.read(ROOT / "setup.cfg")
    scripts = dict(line.split(" = ") for line in
                   cfg["options.entry_points"]["gui_scripts"].strip().splitlines())
    assert scripts == {"rigedit-editor": "rigedit.ui.app:main"}
    proc = subprocess.run([sys.executable, "-m", "rigedit.ui.app", "--screenshot",
                           str(tmp_path / "x.png"), str(tmp_path / "missing")],
                          capture_output=True, text=True, timeout=60, cwd=ROOT)
    assert proc.returncode == 2
    assert "rigedit-editor: " in proc.stderr and "missing" in proc.stderr
    assert "Traceback" not in proc.stderr
