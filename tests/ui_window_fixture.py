"""The editor window fixture shared by the UI tests (a real window under Xvfb).

It opens the bundled quadruped and nothing else: when that rig cannot be loaded the fixture
fails with the loader's message rather than testing some other rig. (Tests that want the
small code-built creature for speed build their own window on ``demo_rig()``.)
"""
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


@pytest.fixture
def window(qtbot, rig_template):
    """The main window on the default rig, reset to its bundled rest state; fails the test
    when a VTK callback raised."""
    from threadpoolctl import threadpool_limits

    from rigedit.ui import MainWindow

    rig = rig_template
    # Every test starts from the bundled rest state and place (tests edit the rig in place,
    # File > Save As moves it).
    rig.skeleton, rig.binding, rig.path = _ORIGINAL.setdefault(
        id(rig), (rig.skeleton, rig.binding, rig.path))
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


def limb_joint(sk, name="fore_cannon_L"):
    """Joint ``name`` (by default the quadruped's left fore cannon, two below a non-branching
    chain: a lower leg), for drag tests; fails the test when the skeleton has no such joint."""
    if name not in sk.index:
        pytest.fail(f"expected a joint {name!r} in the test rig, got {', '.join(sk.names)}",
                    pytrace=False)
    return sk.index[name]
