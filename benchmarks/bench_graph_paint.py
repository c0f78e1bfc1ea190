"""What a repaint of the graph editor's canvas costs with many keys, against drawing each key
as its own QPainter call (the naive way, one Python object and call per key).

Run: ``QT_QPA_PLATFORM=offscreen .venv/bin/python benchmarks/bench_graph_paint.py
[--size WxH] [--rounds N]`` (or under ``xvfb-run``).

Three channels of K keys each (K = 100 ... 100,000) over a 10 s clip, all in view (the worst
case: nothing is culled by time), a noisy curve (mocap-like). Measured in one run, interleaved,
best of ``--rounds``: the canvas's whole picture (``GraphView._paint_background`` into a
pixmap: grid, curves sampled per pixel column, keys, dense keys as touching squares) and the
reference, the same grid and curves with each key drawn by its own ``drawRect`` from a
Python loop. Printed: milliseconds per repaint and the ratio to the reference.
The sampling here is ``np.interp`` (the curves' own cost is bench_curves.py's).
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path
from types import SimpleNamespace

os.environ.setdefault("OMP_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np  # noqa: E402
from PyQt5 import QtCore, QtGui, QtWidgets  # noqa: E402

from rigedit.ui.graph_view import KEY_PX, GraphView, _colour  # noqa: E402

COLOURS = ((0.9, 0.2, 0.2), (0.25, 0.8, 0.25), (0.25, 0.45, 0.95))


def _channel(axis, k, rng):
    times = np.linspace(0.0, 10.0, k)
    values = np.cumsum(rng.normal(0.0, 1.0, k)) * (30.0 / np.sqrt(k)) + 20.0 * axis
    hx = np.column_stack([times, values])
    curve = SimpleNamespace(times=times, values=values, left=hx, right=hx,
                            interpolation=np.array(["linear"] * k, dtype=object))
    return SimpleNamespace(id=("joint", "rotation", axis), colour=COLOURS[axis], curve=curve,
                           sample=lambda t, c=curve: np.interp(t, c.times, c.values))


class NaiveView(GraphView):
    """The reference: keys one drawRect each."""

    def _paint_keys(self, p, channel):
        p.setPen(QtCore.Qt.NoPen)
        p.setBrush(_colour(channel.colour).lighter(130))
        tr, cv = self.transform, channel.curve
        for t, v in zip(cv.times, cv.values):
            x, y = float(tr.x_of(t)), float(tr.y_of(v))
            p.drawRect(QtCore.QRectF(x - KEY_PX / 2, y - KEY_PX / 2, KEY_PX, KEY_PX))


def _paint_ms(view):
    pix = QtGui.QPixmap(view.size())
    t = time.perf_counter()
    view._paint_background(pix)
    return (time.perf_counter() - t) * 1e3


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="1200x400")
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    w, h = (int(s) for s in args.size.split("x"))
    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication([])
    rng = np.random.default_rng(0)
    print(f"canvas {w}x{h}, 3 channels, best of {args.rounds}")
    print(f"{'keys/channel':>12} {'graph ms':>9} {'naive ms':>9} {'ratio':>7}")
    for k in (100, 1_000, 10_000, 100_000):
        chans = [_channel(a, k, rng) for a in range(3)]
        views = []
        for cls in (GraphView, NaiveView):
            v = cls(lambda: 30.0)
            v.resize(w, h)
            v.duration = 10.0
            v.set_channels(chans)
            v.frame_all()
            views.append(v)
        for v in views:   # warm-up: fonts, the first pixmap
            _paint_ms(v)
        best = [np.inf, np.inf]
        for _ in range(args.rounds):
            for i, v in enumerate(views):
                best[i] = min(best[i], _paint_ms(v))
        print(f"{k:>12,} {best[0]:>9.1f} {best[1]:>9.1f} {best[0] / best[1]:>7.3f}")
    app.quit()


if __name__ == "__main__":
    main()
