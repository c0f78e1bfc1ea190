import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from rigedit.model.transforms import (compose_trs, decompose_trs, euler_to_quat,
                                      normalize_quats, quat_to_euler)

angle = st.floats(-179.0, 179.0)


@settings(max_examples=200, deadline=None)
@given(angle, st.floats(-89.0, 89.0), angle)
def test_euler_quat_round_trip(x, y, z):
    q = euler_to_quat([x, y, z], degrees=True)
    assert np.isclose(np.linalg.norm(q), 1.0)
    back = quat_to_euler(q, degrees=True)
    assert np.allclose(back, [x, y, z], atol=1e-6)


def test_euler_order_is_x_first_then_y_then_z():
    x, y, z = np.radians([30.0, 40.0, 50.0])
    rx = np.array([[1, 0, 0], [0, np.cos(x), -np.sin(x)], [0, np.sin(x), np.cos(x)]])
    ry = np.array([[np.cos(y), 0, np.sin(y)], [0, 1, 0], [-np.sin(y), 0, np.cos(y)]])
    rz = np.array([[np.cos(z), -np.sin(z), 0], [np.sin(z), np.cos(z), 0], [0, 0, 1]])
    m = Rotation.from_quat(euler_to_quat([x, y, z])).as_matrix()
    assert np.allclose(m, rz @ ry @ rx)


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 10_000))
def test_compose_decompose_round_trip(seed):
    rng = np.random.default_rng(seed)
    t = rng.normal(size=(5, 3))
    q = Rotation.random(5, random_state=seed).as_quat()
    s = rng.uniform(0.2, 3.0, size=(5, 3))
    m = compose_trs(t, q, s)
    t2, q2, s2 = decompose_trs(m)
    assert np.allclose(t2, t) and np.allclose(s2, s)
    assert np.allclose(np.abs(np.sum(q2 * q, axis=1)), 1.0)


def test_normalize_rejects_zero_quaternion():
    import pytest

    with pytest.raises(ValueError, match="zero quaternion"):
        normalize_quats([0, 0, 0, 0])
