"""The editor window fixture shared by the UI tests (a real window under Xvfb).

It opens the bundled quadruped and nothing else: when that rig cannot be loaded the fixture
fails with the loader's message rather than testing some other rig. (Tests that want the
small code-built creature for speed use ``demo_window``.)
"""
from contextlib import contextmanager

import pytest

import rigedit

_ORIGINAL = {}
RIG = "quadruped"


@pytest.fixture(scope="module")
def rig_template():
    try:
        return rigedit.load_rig(RIG)
    except (ValueError, OSError) as exc:
        pytest.fail(f"the UI tests' rig {RIG!r} did not load: {exc}", pytrace=False)


@contextmanager
def editor_window(qtbot, rig, size=(1100, 750)):
    """A shown main window on ``rig``; on exit it is closed, and the test fails when a VTK
    callback raised meanwhile."""
    from threadpoolctl import threadpool_limits

    from rigedit.ui import MainWindow

    with threadpool_limits(1):
        w = MainWindow(rig)
        qtbot.addWidget(w)
        w.resize(*size)
        w.show()
        qtbot.waitExposed(w)
        w.plotter.render()
        yield w
        errors = list(w.gizmos.errors)
        w.close()
    assert errors == [], "exceptions in VTK callbacks:\n" + "\n".join(errors)


@pytest.fixture
def window(qtbot, rig_template):
    """The main window on the bundled quadruped, reset to its bundled rest state."""
    rig = rig_template
    # Every test starts from the bundled rest state and place (tests edit the rig in place,
    # File > Save As moves it).
    rig.skeleton, rig.binding, rig.path = _ORIGINAL.setdefault(
        id(rig), (rig.skeleton, rig.binding, rig.path))
    with editor_window(qtbot, rig) as w:
        yield w


@pytest.fixture
def demo_window(qtbot):
    """The main window on the small code-built creature (``demo_rig()``, 19 joints), chosen
    for speed where the rig does not matter."""
    from rigedit.ui.fallback import demo_rig

    with editor_window(qtbot, demo_rig()) as w:
        yield w


@pytest.fixture
def humanoid_window(qtbot):
    """The main window on a freshly loaded bundled humanoid (tests may change it)."""
    with editor_window(qtbot, rigedit.load_rig("humanoid")) as w:
        yield w


def menu_action(window, menu, text):
    """The action ``text`` (without '&' and '...') of the window's menu ``menu``."""
    def clean(t):
        return t.replace("&", "").rstrip(".").strip()

    for top in window.menuBar().actions():
        if clean(top.text()) == menu:
            for act in top.menu().actions():
                if clean(act.text()) == text:
                    return act
    pytest.fail(f"expected an action {text!r} in the {menu} menu", pytrace=False)


def answer_file_dialog(monkeypatch, name, *answers):
    """Make the static ``QFileDialog.<name>`` ("getOpenFileName", "getSaveFileName",
    "getExistingDirectory") return ``answers`` in turn, then fail the test (the action asked
    more often than expected); returns the list of the captions asked."""
    from PyQt5 import QtWidgets

    asked = []
    queue = list(answers)

    def dialog(parent, caption, *args, **kwargs):
        asked.append(caption)
        assert queue, f"unexpected file dialog {caption!r}"
        answer = str(queue.pop(0))
        return answer if name == "getExistingDirectory" else (answer, "")

    monkeypatch.setattr(QtWidgets.QFileDialog, name, staticmethod(dialog))
    return asked


def limb_joint(sk, name="fore_cannon_L"):
    """Joint ``name`` (by default the quadruped's left fore cannon, two below a non-branching
    chain: a lower leg), for drag tests; fails the test when the skeleton has no such joint."""
    if name not in sk.index:
        pytest.fail(f"expected a joint {name!r} in the test rig, got {', '.join(sk.names)}",
                    pytrace=False)
    return sk.index[name]


def send_mouse(widget, kind, x, y):
    """Send a left-button "press", "move" (button held) or "release" at (x, y) to a Qt
    widget."""
    from PyQt5 import QtCore, QtGui, QtWidgets

    types = {"press": QtCore.QEvent.MouseButtonPress, "move": QtCore.QEvent.MouseMove,
             "release": QtCore.QEvent.MouseButtonRelease}
    buttons = QtCore.Qt.NoButton if kind == "release" else QtCore.Qt.LeftButton
    ev = QtGui.QMouseEvent(types[kind], QtCore.QPointF(x, y), QtCore.Qt.LeftButton, buttons,
                           QtCore.Qt.NoModifier)
    QtWidgets.QApplication.sendEvent(widget, ev)
