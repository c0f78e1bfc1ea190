"""The editor window fixture shared by the UI tests (a real window under Xvfb)."""
import warnings

import pytest

import rigedit

_ORIGINAL = {}


def _default_rig():
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return rigedit.load_rig()
    except (ValueError, OSError):
        from rigedit.ui.fallback import demo_rig

        return demo_rig()


@pytest.fixture(scope="module")
def rig_template():
    return _default_rig()


@pytest.fixture
def window(qtbot, rig_template):
    """The main window on the default rig, reset to its bundled rest state; fails the test
    when a VTK callback raised."""
    from threadpoolctl import threadpool_limits

    from rigedit.ui import MainWindow

    rig = rig_template
    # Every test starts from the bundled rest state (tests edit the rig in place).
    rig.skeleton, rig.binding = _ORIGINAL.setdefault(id(rig), (rig.skeleton, rig.binding))
    with threadpool_limits(1):
        w = MainWindow(rig)
        qtbot.addWidget(w)
        w.resize(1100, 750)
        w.show()
        qtbot.waitExposed(w)
        w.plotter.render()
        yield w
        errors = list(w.gizmos.errors)
        w.close()
    assert errors == [], "exceptions in VTK callbacks:\n" + "\n".join(errors)


def limb_joint(sk):
    """A joint two below a non-branching chain (a lower leg), for drag tests."""
    for name in ("fore_cannon_L", "front_foot_L", "hind_cannon_L"):
        if name in sk.index:
            return sk.index[name]
    return len(sk) - 1
