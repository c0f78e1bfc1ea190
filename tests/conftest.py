import atexit
import os
import shutil
import socket
import tempfile

os.environ.setdefault("OMP_NUM_THREADS", "1")
# The editor writes recovery entries and its error log to the user's cache folder
# ($XDG_CACHE_HOME/rigedit): keep the tests' (and their subprocesses') out of the real one.
os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(prefix="rigedit-test-cache-")
atexit.register(shutil.rmtree, os.environ["XDG_CACHE_HOME"], True)
# The weights cache (rigedit/binding/weights_cache.py) is off for the whole session: a test
# that loads a folder without weights.npz computes them, as before; its own tests point it at
# tmp_path.
os.environ["RIGEDIT_CACHE_DIR"] = "off"

import sys
from pathlib import Path

import pytest

# Tests sit in folders mirroring the packages (tests/model/, tests/io/, ...) and some share
# tables by importing another test module by name (``from test_gltf import SAMPLES``): every
# folder is importable, whatever order pytest collects them in.
for _folder in sorted(p for p in Path(__file__).resolve().parent.rglob("*")
                      if p.is_dir() and p.name != "__pycache__"):
    if str(_folder) not in sys.path:
        sys.path.append(str(_folder))

# The editor window fixture (`window`, `demo_window`, `rig_template`) for the UI tests.
pytest_plugins = ["ui_window_fixture"]

from builders import cylinder_rig


@pytest.fixture
def cyl_rig():
    return cylinder_rig()


# The bundled rigs, loaded once per test module (a module may change its copy).
@pytest.fixture(scope="module")
def humanoid():
    import rigedit

    return rigedit.load_rig("humanoid")


@pytest.fixture(scope="module")
def quadruped():
    import warnings

    import rigedit

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rigedit.load_rig("quadruped")


# ---------------------------------------------------------------------- UI test environment
# The UI tests need pytest-qt and an X display (Xvfb, started by pytest-xvfb). When either is
# missing they must FAIL, never skip: a skipped UI suite looks green. pytest-xvfb itself only
# prints a note when Xvfb is not installed and runs on whatever DISPLAY there is (or none, and
# then Qt aborts the whole process), so check here, before any fixture creates a QApplication.
UI_FIXTURES = {"qtbot", "qapp", "window", "demo_window"}
UI_PROBLEM = pytest.StashKey[object]()


def _display_reachable(display):
    """Whether an X server answers on ``display`` (":N", ":N.S" or "host:N")."""
    host, _, number = display.rpartition(":")
    try:
        n = int(number.split(".")[0])
    except ValueError:
        return False
    if host in ("", "unix"):
        targets = [(socket.AF_UNIX, f"/tmp/.X11-unix/X{n}"),
                   (socket.AF_UNIX, f"\0/tmp/.X11-unix/X{n}")]  # Linux abstract socket
    else:
        targets = [(socket.AF_INET, (host, 6000 + n))]
    for family, address in targets:
        with socket.socket(family, socket.SOCK_STREAM) as s:
            s.settimeout(2.0)
            try:
                s.connect(address)
                return True
            except OSError:
                continue
    return False


def ui_environment_problem(config, environ=os.environ):
    """Why the UI tests cannot run here, or None."""
    plugins = {getattr(p, "__name__", "") for p in config.pluginmanager.get_plugins()}
    if "pytestqt.plugin" not in plugins:
        return ("pytest-qt is not installed (or disabled): the UI tests need it "
                "(pip install -e '.[test]')")
    try:
        import pytest_xvfb
        xvfb_running = pytest_xvfb.xvfb_instance is not None
    except ImportError:
        xvfb_running = False
    if environ.get("CI") and not xvfb_running:
        return ("CI is set but pytest-xvfb did not start Xvfb (is the Xvfb binary and "
                "pytest-xvfb installed?): the UI tests run under Xvfb in CI")
    platform = environ.get("QT_QPA_PLATFORM", "xcb")
    if platform.split(":")[0] not in ("xcb", ""):
        return (f"QT_QPA_PLATFORM={platform}: the UI tests need the xcb platform on an X "
                "display (pyvistaqt's interactor does not work offscreen)")
    display = environ.get("DISPLAY")
    if not display:
        return ("no X display: DISPLAY is unset and pytest-xvfb did not start Xvfb "
                "(install the Xvfb binary, e.g. apt-get install xvfb)")
    if not _display_reachable(display):
        return f"no X server answers on DISPLAY={display}"
    return None


def is_ui_test(item):
    return (item.get_closest_marker("ui") is not None
            or bool(UI_FIXTURES & set(getattr(item, "fixturenames", ()))))


def pytest_collection_modifyitems(config, items):
    if any(is_ui_test(item) for item in items):
        config.stash[UI_PROBLEM] = ui_environment_problem(config)


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item):
    """Fail (not skip) each UI test, before its fixtures run, when the environment cannot
    run it."""
    problem = item.config.stash.get(UI_PROBLEM, None)
    if problem and is_ui_test(item):
        pytest.fail(f"UI test environment: {problem}", pytrace=False)
