"""A contact sheet of a rendered video: a few of its frames, evenly spaced, in a grid (PNG),
pixels as ``rigedit render`` wrote them (nothing redrawn or resampled)."""
from __future__ import annotations

import numpy as np

from ..io.atomic import atomic_write

__all__ = ["write_sheet"]


def write_sheet(video, out, count=6, columns=3):
    """Tile ``count`` frames of ``video`` (MP4 or GIF) into ``out`` (PNG), written atomically.

    Parameters
    ----------
    video, out : Path
    count, columns : int
        Frames taken (fewer when the video has fewer) and frames per row.

    Returns
    -------
    (int, int)
        The sheet's height and width in pixels.
    """
    import imageio.v3 as iio

    frames = np.asarray(iio.imread(video, index=None))[..., :3]   # (T, H, W, 3) uint8
    picked = frames[np.linspace(0, len(frames), min(count, len(frames)), endpoint=False,
                                dtype=int)]
    rows = -(-len(picked) // columns)
    cols = min(columns, len(picked))
    _, h, w, _ = picked.shape
    sheet = np.full((rows * h, cols * w, 3), 255, dtype=np.uint8)
    for i, frame in enumerate(picked):
        r, c = divmod(i, cols)
        sheet[r * h:(r + 1) * h, c * w:(c + 1) * w] = frame
    with atomic_write(out, "wb", suffix=".png") as fh:
        fh.write(iio.imwrite("<bytes>", sheet, extension=".png"))
    return sheet.shape[:2]
