"""Adversarial sampling of Bezier curves: handles reaching past the next key or sitting on
their key, keys a nanosecond apart, values of a million; many samples solved at once must each
give what solving it alone gives (a converged sample must not be thrown away while others
still iterate)."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rigedit.animation.bezier import solve_u
from rigedit.animation.curve import Curve


def bisect_sample(curve, ts, steps=200):
    """Reference values of ``curve`` at ``ts``: x(u) = t by plain bisection to the last bit."""
    seg = curve.segments()
    i = np.clip(np.searchsorted(curve.times, ts, side="right") - 1, 0, len(curve) - 2)
    x, y = seg[i][:, :, 0], seg[i][:, :, 1]

    def at(p, u):
        w = 1 - u
        return (w ** 3 * p[:, 0] + 3 * w * w * u * p[:, 1] + 3 * w * u * u * p[:, 2]
                + u ** 3 * p[:, 3])

    lo, hi = np.zeros(len(ts)), np.ones(len(ts))
    for _ in range(steps):
        m = 0.5 * (lo + hi)
        below = at(x, m) < ts
        lo, hi = np.where(below, m, lo), np.where(below, hi, m)
    return at(y, 0.5 * (lo + hi))


def test_a_batch_of_samples_solves_each_as_alone():
    # x(u) = u^3 (both handles on the first key) converges from above while segments with
    # handles near their far ends keep the loop going: the converged root used to be
    # bisected away (u off by 2e-7)
    rng = np.random.default_rng(1)
    a, b = rng.random(200) ** 30, 1 - rng.random(200) ** 30
    x = np.r_[[[0.0, 0.0, 0.0, 1.0]],
              np.stack([np.zeros(200), np.minimum(a, b), np.maximum(a, b), np.ones(200)], 1)]
    t = np.r_[1.2037015644050797e-4, rng.random(200)]
    together = solve_u(x, t)
    alone = np.array([solve_u(x[k:k + 1], t[k:k + 1])[0] for k in range(len(t))])
    np.testing.assert_allclose(together, alone, rtol=0, atol=1e-10)
    assert abs(together[0] - t[0] ** (1 / 3)) < 1e-12


def test_a_graph_drawing_of_free_handles_is_exact():
    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(60):
        t = np.r_[0, np.cumsum(rng.uniform(0.1, 1, 3))]
        v = rng.normal(size=4) * 90
        left = np.stack([t - rng.uniform(0, 1, 4), v + rng.normal(size=4) * 90], 1)
        right = np.stack([t + rng.uniform(0, 1, 4), v + rng.normal(size=4) * 90], 1)
        c = Curve(t, v, "bezier", left, right, "free", "free")
        ts = np.linspace(t[0], t[-1], 1000)      # one sample per pixel column, in one call
        worst = max(worst, np.abs(c.sample(ts) - bisect_sample(c, ts)).max())
    assert worst < 1e-7     # degrees; was 2e-5


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-9, 1), min_size=1, max_size=4),      # log10 of the key gaps
       st.lists(st.floats(-10, 6), min_size=10, max_size=10),   # log10 of the handle reach
       st.lists(st.floats(-1e6, 1e6), min_size=15, max_size=15),
       st.sampled_from([0.0, 1e5]))
def test_any_handles_keep_a_function_of_time_without_nan(gaps, reach, numbers, start):
    k = len(gaps) + 1
    t = start + np.r_[0.0, np.cumsum(10.0 ** np.array(gaps))]
    v = np.array(numbers[:k])
    r = 10.0 ** np.array(reach[:2 * k]).reshape(k, 2)
    dv = np.resize(numbers[5:], (k, 2))
    c = Curve(t, v, "bezier", np.stack([t - r[:, 0], v + dv[:, 0]], 1),
              np.stack([t + r[:, 1], v + dv[:, 1]], 1), "free", "free")
    seg = c.segments()
    # monotone time control points: x(u) increasing, x(u) = t one root (no loop)
    assert np.all(np.diff(seg[:, :, 0], axis=1) >= -1e-9 * np.maximum(1.0, np.abs(t).max()))
    ts = np.unique(np.r_[np.linspace(t[0], t[-1], 301), t, np.nextafter(t, np.inf)])
    s = c.sample(ts)
    assert np.all(np.isfinite(s))
    i = np.clip(np.searchsorted(t, ts, side="right") - 1, 0, k - 2)
    y = seg[i][:, :, 1]
    tol = 1e-9 * np.maximum(1.0, np.abs(y).max(axis=1))
    assert np.all((s >= y.min(axis=1) - tol) & (s <= y.max(axis=1) + tol))   # inside its hull
    np.testing.assert_allclose(c.sample(t), v, rtol=0, atol=1e-9 * max(1.0, np.abs(v).max()))


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-9, 2), min_size=1, max_size=7),       # log10 of the key gaps
       st.lists(st.floats(-6, 3), min_size=8, max_size=8),       # log10 of the value steps
       st.lists(st.booleans(), min_size=8, max_size=8))
def test_auto_clamped_never_overshoots_on_any_spacing(gaps, steps, down):
    # monotonic runs and turns, keys a nanosecond to 100 s apart, steps of 1e-6 to 1000
    t = np.r_[0.0, np.cumsum(10.0 ** np.array(gaps))]
    v = np.cumsum(np.where(down[:len(t)], -1.0, 1.0) * 10.0 ** np.array(steps[:len(t)]))
    c = Curve(t, v)
    for k in range(len(t) - 1):
        s = c.sample(np.linspace(t[k], t[k + 1], 41))
        lo, hi = sorted(v[k:k + 2])
        slack = 1e-12 * max(1.0, np.abs(v).max())
        assert s.min() >= lo - slack and s.max() <= hi + slack
