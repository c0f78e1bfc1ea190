"""Morph targets: the data, the displacement sum, and skinning with morphs."""
import numpy as np
import pytest

from rigedit.model.morph import MorphTargets


def _targets(V=6, seed=0):
    rng = np.random.default_rng(seed)
    deltas = np.zeros((2, V, 3), np.float32)
    deltas[0, :2] = rng.normal(size=(2, 3))                   # moves vertices 0 and 1
    deltas[1, 3:] = rng.normal(size=(V - 3, 3))
    return MorphTargets(("smile", "blink"), deltas)


def test_apply_is_the_weighted_sum_and_none_when_all_weights_are_zero():
    mt = _targets()
    assert mt.apply([0.0, 0.0]) is None and mt.apply(None) is None
    got = mt.apply([0.5, -2.0])
    want = 0.5 * mt.deltas[0] - 2.0 * mt.deltas[1]
    np.testing.assert_allclose(got, want, atol=1e-6)
    assert list(mt.moved_rows(0)) == [0, 1]
    np.testing.assert_allclose(mt.apply({"blink": 1.0}), mt.deltas[1])
    buf = np.full((6, 3), 9.0, np.float32)
    assert mt.apply({"smile": 1.0, "other": 3.0}, out=buf) is buf
    np.testing.assert_allclose(buf, mt.deltas[0])


def test_default_weights_apply_when_none_are_given():
    mt = MorphTargets(("a",), np.ones((1, 2, 3)), default_weights=[0.5])
    np.testing.assert_allclose(mt.apply(None), 0.5)
    np.testing.assert_allclose(mt.weights_array({}), [0.5])


@pytest.mark.parametrize("kwargs", [
    dict(names=("a", "a"), deltas=np.zeros((2, 3, 3))),
    dict(names=("a",), deltas=np.zeros((2, 3, 3))),
    dict(names=("a",), deltas=np.zeros((1, 3, 2))),
    dict(names=("a",), deltas=np.full((1, 3, 3), np.nan)),
    dict(names=("a",), deltas=np.zeros((1, 3, 3)), normal_deltas=np.zeros((1, 2, 3))),
    dict(names=("a",), deltas=np.zeros((1, 3, 3)), default_weights=[1.0, 2.0])])
def test_malformed_targets_are_refused(kwargs):
    with pytest.raises(ValueError):
        MorphTargets(**kwargs)
