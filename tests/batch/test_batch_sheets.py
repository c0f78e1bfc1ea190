"""Contact sheets of rendered videos: frames evenly spaced, tiled without resampling."""
import imageio.v3 as iio
import numpy as np

from rigedit.batch.sheets import write_sheet


def test_a_sheet_tiles_evenly_spaced_frames_in_order(tmp_path):
    frames = np.zeros((10, 8, 12, 3), dtype=np.uint8)
    for i in range(10):
        frames[i] = 20 * i   # each frame one grey level: which frame a tile is
    video = tmp_path / "v.gif"
    iio.imwrite(video, frames, loop=0)
    out = tmp_path / "sheet.png"
    assert write_sheet(video, out, count=6, columns=3) == (16, 36)
    sheet = iio.imread(out)
    tiles = [sheet[r * 8:(r + 1) * 8, c * 12:(c + 1) * 12] for r in range(2) for c in range(3)]
    levels = [int(np.median(t)) for t in tiles]
    assert levels == [20 * i for i in (0, 1, 3, 5, 6, 8)]   # floor(k * 10 / 6)
    assert not list(tmp_path.glob(".*"))


def test_a_short_video_gives_fewer_tiles(tmp_path):
    frames = np.full((2, 4, 4, 3), 200, dtype=np.uint8)
    frames[1] = 100   # a GIF writer merges equal frames
    video = tmp_path / "v.gif"
    iio.imwrite(video, frames, loop=0)
    assert write_sheet(video, tmp_path / "s.png") == (4, 8)
