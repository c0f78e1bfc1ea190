import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import pytest

from builders import cylinder_rig


@pytest.fixture
def cyl_rig():
    return cylinder_rig()
