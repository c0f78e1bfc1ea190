import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import pytest

# The editor window fixture (`window`, `rig_template`) for the UI tests.
pytest_plugins = ["ui_window_fixture"]

from builders import cylinder_rig


@pytest.fixture
def cyl_rig():
    return cylinder_rig()
