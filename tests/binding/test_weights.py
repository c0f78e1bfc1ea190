import numpy as np
import pytest

from builders import chain_skeleton, cylinder
from rigedit.binding.weights import compute_weights, point_segment_distance


def test_point_segment_distance_matches_brute_force():
    rng = np.random.default_rng(0)
    p = rng.normal(size=(200, 3))
    s, e = rng.normal(size=(7, 3)), rng.normal(size=(7, 3))
    e[3] = s[3]  # a point segment
    ref = np.empty((200, 7))
    for i in range(200):
        for k in range(7):
            d = e[k] - s[k]
            t = 0.0 if not d.any() else np.clip(np.dot(p[i] - s[k], d) / np.dot(d, d), 0, 1)
            ref[i, k] = np.linalg.norm(p[i] - s[k] - t * d)
    assert np.allclose(point_segment_distance(p, s, e), ref, atol=1e-9)


def test_idw_weights_follow_the_nearest_bone():
    sk = chain_skeleton(3)
    v, _ = cylinder()
    idx, w = compute_weights(v, sk, "idw", max_influences=2)
    assert idx.shape == (len(v), 2)
    assert np.allclose(w.sum(axis=1), 1.0)
    y = v[:, 1]
    # j0 owns y in [0, 1], j1 [1, 2], j2 (its tail) [2, 3]: the top influence follows.
    assert np.all(idx[(y > 0.2) & (y < 0.8), 0] == 0)
    assert np.all(idx[(y > 1.2) & (y < 1.8), 0] == 1)
    assert np.all(idx[(y > 2.2) & (y < 2.8), 0] == 2)
    # Mid-bone vertices are dominated by their bone; at a joint the two neighbours share.
    assert w[(y > 1.4) & (y < 1.6), 0].min() > 0.85
    near_joint = np.abs(y - 1.0) < 0.06
    assert np.all(w[near_joint, 1] > 0.2)


def test_compute_weights_rejects_unknown_method_and_bad_k():
    sk = chain_skeleton(2)
    with pytest.raises(ValueError, match="unknown weights method 'magic'"):
        compute_weights(np.zeros((3, 3)), sk, "magic")
    with pytest.raises(ValueError, match="max_influences"):
        compute_weights(np.zeros((3, 3)), sk, "idw", max_influences=9)
