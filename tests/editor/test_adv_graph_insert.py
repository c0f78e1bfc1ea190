"""Adversarial Insert (the graph editor's I): a key inserted on any curve (bezier segments
with free, aligned or automatic handles, linear and constant segments, before the first key
and after the last) must leave the motion as it was, as the graph editor promises."""
import numpy as np
import pytest

from builders import cylinder_rig
from rigedit.animation.curve import HANDLE_TYPES, Curve
from rigedit.editor import graph_commands as gc
from rigedit.editor.document import Document

RX = gc.ChannelId("j1", "rotation", 0)
RZ = gc.ChannelId("j1", "rotation", 2)
TX = gc.ChannelId("j1", "translation", 0)


def random_curve(rng):
    k = int(rng.integers(2, 7))
    t = np.r_[0.0, np.cumsum(rng.uniform(0.05, 0.5, k - 1))]
    v = rng.normal(size=k) * 60
    left = np.stack([t - rng.uniform(0, 0.6, k), v + rng.normal(size=k) * 60], 1)
    right = np.stack([t + rng.uniform(0, 0.6, k), v + rng.normal(size=k) * 60], 1)
    return Curve(t, v, rng.choice(["constant", "linear", "bezier"], k, p=[0.2, 0.2, 0.6]),
                 left, right, rng.choice(HANDLE_TYPES, k), rng.choice(HANDLE_TYPES, k))


@pytest.mark.parametrize("seed", range(40))
def test_inserting_a_key_keeps_the_curve(seed):
    rng = np.random.default_rng(seed)
    c = random_curve(rng)
    ts = np.linspace(c.times[0] - 0.5, c.times[-1] + 0.5, 1201)
    for t in np.r_[rng.uniform(c.times[0] - 0.3, c.times[-1] + 0.3, 4)]:
        out = c.with_key(t, keep_shape=True)
        assert len(out) == len(c) + 1 and t in out.times
        scale = max(1.0, np.abs(c.sample(ts)).max())
        np.testing.assert_allclose(out.sample(ts), c.sample(ts), rtol=0, atol=1e-7 * scale)


def test_a_key_inserted_on_a_hold_keeps_the_hold():
    c = Curve([0, 1], [0, 90], "constant")
    out = c.with_key(0.5, keep_shape=True)
    assert out.interpolation[1] == "constant" and out.sample(0.99) == 0.0
    # the plain insert makes the new key bezier: the hold became a ramp from 0.5 to 1
    assert c.with_key(0.5).sample(0.75) > 10


def test_insert_in_the_editor_keeps_what_every_channel_plays():
    doc = Document(cylinder_rig())   # j1 turns 60 degrees about z at 0.5 s
    rz = Curve([0, 0.4, 1.0], [0, 90, 30], left_type=["auto", "free", "vector"],
               right_type=["auto_clamped", "free", "aligned"],
               left=[[-0.1, 0], [0.3, 120], [0.8, 30]], right=[[0.1, 0], [0.45, 60], [1.2, 0]])
    gc.edit_curves(doc, {RZ: rz, RX: Curve([0, 0.7], [10, -20], "linear"),
                         TX: Curve([0, 0.2, 1.0], [0, 0.5, 0.1])}, "Keys")
    times = np.linspace(0, 1, 101)

    def poses():
        out = []
        for t in times:
            doc.set_time(float(t))
            out.append(np.r_[doc.pose.rotation.ravel(), doc.pose.translation.ravel()])
        return np.array(out)

    before = poses()
    for t in (0.2, 0.55, 0.9):
        assert gc.insert_keys(doc, [RX, RZ, TX], t) == 3
    after = poses()
    # was up to 3-6 degrees off between the new key and its neighbours
    np.testing.assert_allclose(after, before, atol=1e-9)
    assert all(len(gc.channel_curve(doc.clip, c)) >= 5 for c in (RX, RZ, TX))
