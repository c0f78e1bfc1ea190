"""The UI tests fail, never skip, when pytest-qt or an X display is missing: conftest.py
checks before any fixture creates a QApplication (without a display Qt aborts the whole run;
an importorskip would hide the UI suite behind a green result)."""
from testpaths import REPO
import os
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

from conftest import ui_environment_problem

ROOT = REPO


def test_a_ui_test_fails_without_a_display():
    # -p no:xvfb and no DISPLAY: what a machine without the Xvfb binary gives (pytest-xvfb
    # then only prints a note). The run fails with the reason, it does not skip or abort.
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "CI")}
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "-p", "no:xvfb",
                           "tests/ui/test_ui_app.py::test_app_bad_rig_exits_with_message"],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "UI test environment: no X display" in proc.stdout
    assert "1 error" in proc.stdout and "skipped" not in proc.stdout


def _config(with_qt=True):
    """What ui_environment_problem reads of pytest's config: the plugin modules."""
    plugins = [SimpleNamespace(__name__="pytestqt.plugin")] if with_qt else []
    return SimpleNamespace(pluginmanager=SimpleNamespace(get_plugins=lambda: plugins))


@pytest.mark.ui
def test_environment_problems_are_named(pytestconfig):
    display = os.environ["DISPLAY"]  # pytest-xvfb's display, or the machine's
    assert ui_environment_problem(pytestconfig) is None
    assert ui_environment_problem(_config(), {"DISPLAY": display}) is None
    assert "pytest-qt is not installed" in ui_environment_problem(_config(False),
                                                                  {"DISPLAY": display})
    assert "no X display" in ui_environment_problem(_config(), {})
    assert "no X server answers on DISPLAY=:987" in ui_environment_problem(
        _config(), {"DISPLAY": ":987"})
    assert "QT_QPA_PLATFORM=offscreen" in ui_environment_problem(
        _config(), {"DISPLAY": display, "QT_QPA_PLATFORM": "offscreen"})


@pytest.mark.ui
def test_ci_requires_xvfb(pytestconfig, monkeypatch):
    import pytest_xvfb

    display = os.environ["DISPLAY"]
    if pytest_xvfb.xvfb_instance is not None:
        assert ui_environment_problem(_config(), {"CI": "true", "DISPLAY": display}) is None
    monkeypatch.setattr(pytest_xvfb, "xvfb_instance", None)
    assert "CI is set but pytest-xvfb did not start Xvfb" in ui_environment_problem(
        _config(), {"CI": "true", "DISPLAY": display})
    assert ui_environment_problem(_config(), {"DISPLAY": display}) is None  # locally: fine
