"""Tile frames of videos made by ``rigedit render`` into one contact sheet (PNG).

Usage::

    .venv/bin/python docs/make_sheet.py OUT.png ROW1.gif [ROW2.gif ...] [--frames N]

Each video becomes one row of ``N`` frames (6 by default) taken evenly over it, the first
frame included and the last one left out (a looping clip's last frame repeats its first).
The rows must have the same frame width; nothing is drawn or resampled, so the sheet shows
exactly what ``rigedit render`` wrote.
"""
from __future__ import annotations

import argparse
import sys

import numpy as np


def pick_frames(frames, n):
    """``n`` frames evenly over ``frames`` (index ``floor(i * len / n)``).

    Parameters
    ----------
    frames : (T, H, W, C) uint8
    n : int

    Returns
    -------
    (n, H, W, C) uint8
    """
    if n < 1 or len(frames) < n:
        raise ValueError(f"expected at least {n} frames, got {len(frames)}")
    return frames[(np.arange(n) * len(frames)) // n]


def make_sheet(videos, out, n=6):
    """Read each video, take ``n`` frames, stack the rows and write ``out``. Returns the
    sheet's (height, width)."""
    import imageio.v3 as iio

    rows = []
    for path in videos:
        frames = np.asarray(iio.imread(path, index=None))[..., :3]
        rows.append(np.concatenate(list(pick_frames(frames, n)), axis=1))
    widths = {r.shape[1] for r in rows}
    if len(widths) != 1:
        raise ValueError(f"expected rows of one width, got {sorted(widths)} pixels")
    sheet = np.concatenate(rows, axis=0)
    iio.imwrite(out, sheet, optimize=True)  # lossless: Pillow tries harder
    return sheet.shape[:2]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out")
    p.add_argument("videos", nargs="+")
    p.add_argument("--frames", type=int, default=6)
    args = p.parse_args(argv)
    h, w = make_sheet(args.videos, args.out, args.frames)
    print(f"wrote {args.out}: {len(args.videos)} rows of {args.frames} frames, {w}x{h}")


if __name__ == "__main__":
    sys.exit(main())
