"""The off-screen recorder: frame count and size read back with imageio, moving frames, GIF,
cancel leaves no file, the camera of a view is copied."""
import imageio.v3 as iio
import numpy as np
import pytest

from builders import cylinder_rig
from rigedit.errors import RigFileError
from rigedit.render.recorder import RecordingCancelled, frame_times, record_clip

SIZE = (160, 120)


@pytest.fixture(scope="module")
def rig():
    return cylinder_rig()


def read_frames(path):
    return np.stack(list(iio.imiter(path)))


def test_frame_times_are_exact_multiples_of_the_step():
    t = frame_times(1.0, 30)
    assert len(t) == 30 and t[0] == 0.0 and t[7] == 7 / 30
    assert len(frame_times(0.5, 24, start=1.0)) == 12


def test_mp4_has_the_requested_frames_and_size_and_they_move(rig, tmp_path):
    path = tmp_path / "bend.mp4"
    seen = []
    n = record_clip(rig, rig.clips["bend"], path, fps=10, duration=1.0, size=SIZE,
                    progress=lambda done, total: seen.append((done, total)))
    assert n == 10 and seen[-1] == (10, 10) and len(seen) == 10
    frames = read_frames(path)
    assert frames.shape == (10, SIZE[1], SIZE[0], 3)
    # the cylinder bends 60 degrees at t = 0.5: that frame differs from the first one
    diff = np.abs(frames[5].astype(int) - frames[0].astype(int)).mean()
    assert diff > 6.5  # measured 13.0 (mean absolute difference, 0-255 per channel)
    assert [p.name for p in tmp_path.iterdir()] == ["bend.mp4"]


def test_gif_with_orbit(rig, tmp_path):
    path = tmp_path / "turn.gif"
    assert record_clip(rig, None, path, fps=8, duration=0.5, size=SIZE, orbit=90) == 4
    frames = read_frames(path)
    assert frames.shape[:3] == (4, SIZE[1], SIZE[0])
    assert np.abs(frames[3].astype(int) - frames[0].astype(int)).mean() > 8.5  # measured 16.9


@pytest.mark.parametrize("suffix", [".mp4", ".gif"])
def test_cancel_keeps_an_existing_file_and_leaves_no_temporary(rig, tmp_path, suffix):
    # frames are still queued for the writer thread when the cancel comes
    path = tmp_path / f"out{suffix}"
    path.write_bytes(b"old video")
    with pytest.raises(RecordingCancelled):
        record_clip(rig, rig.clips["bend"], path, fps=10, duration=1.0, size=SIZE,
                    progress=lambda done, total: done < 3)
    assert path.read_bytes() == b"old video"
    assert [p.name for p in tmp_path.iterdir()] == [path.name]


def test_camera_dict_is_used(rig, tmp_path):
    a, b = tmp_path / "a.gif", tmp_path / "b.gif"
    record_clip(rig, None, a, fps=4, duration=0.25, size=SIZE)
    record_clip(rig, None, b, fps=4, duration=0.25, size=SIZE,
                camera={"position": (6, 1.5, 0), "focal_point": (0, 1.5, 0), "up": (0, 1, 0)})
    fa, fb = read_frames(a)[0], read_frames(b)[0]
    assert np.abs(fa.astype(int) - fb.astype(int)).mean() > 11.0  # measured 22.0


def test_rejects_bad_arguments(rig, tmp_path):
    with pytest.raises(RigFileError, match="ending in"):
        record_clip(rig, None, tmp_path / "x.avi")
    with pytest.raises(ValueError, match="even"):
        record_clip(rig, None, tmp_path / "x.mp4", size=(161, 120))
    with pytest.raises(RigFileError, match="folder"):
        record_clip(rig, None, tmp_path / "missing" / "x.mp4", size=SIZE)


def test_an_encoder_error_in_the_writer_thread_is_raised_once_and_leaves_no_temporary(
        rig, tmp_path, monkeypatch):
    import threading

    from rigedit.render import video_writer

    path = tmp_path / "out.mp4"
    path.write_bytes(b"old video")
    real_append, written, done = video_writer.VideoWriter.append, [], []

    def failing_append(self, frame):
        if len(written) == 3:
            raise OSError("ffmpeg: No space left on device")
        real_append(self, frame)
        written.append(frame.shape)

    thread_errors = []
    monkeypatch.setattr(video_writer.VideoWriter, "append", failing_append)
    monkeypatch.setattr(threading, "excepthook", thread_errors.append)
    with pytest.raises(OSError, match="No space left on device"):
        record_clip(rig, rig.clips["bend"], path, fps=10, duration=2.0, size=SIZE,
                    progress=lambda d, total: done.append(d))
    assert thread_errors == []          # one error, raised in the caller, none in the thread
    assert [shape[:2] for shape in written] == [(SIZE[1], SIZE[0])] * 3
    assert len(done) < 20               # stopped at the next frame handed over, not the end
    assert path.read_bytes() == b"old video"
    assert [p.name for p in tmp_path.iterdir()] == ["out.mp4"]


def test_progress_follows_the_one_protocol_and_its_cancel_stops_the_recording(rig, tmp_path):
    from rigedit.progress import Cancelled

    seen = []
    path = tmp_path / "bend.gif"
    assert record_clip(rig, rig.clips["bend"], path, fps=8, duration=0.5, size=SIZE,
                       progress=lambda fraction, stage: seen.append((fraction, stage))) == 4
    assert seen == [(0.25, "record"), (0.5, "record"), (0.75, "record"), (1.0, "record")]

    def cancel(fraction, stage=None):
        if fraction >= 0.5:
            raise Cancelled

    path.write_bytes(b"old video")
    with pytest.raises(RecordingCancelled) as info:   # what the editor catches today
        record_clip(rig, rig.clips["bend"], path, fps=8, duration=0.5, size=SIZE,
                    progress=cancel)
    assert isinstance(info.value, Cancelled)          # and the one cancel of every job
    assert path.read_bytes() == b"old video"
    assert [p.name for p in tmp_path.iterdir()] == [path.name]


def test_the_older_frame_callback_still_works_and_says_it_is_deprecated(rig, tmp_path):
    seen = []
    with pytest.warns(DeprecationWarning, match="progress\\(fraction, stage\\)"):
        record_clip(rig, None, tmp_path / "a.gif", fps=8, duration=0.25, size=SIZE,
                    progress=lambda done, total: seen.append((done, total)))
    assert seen == [(1, 2), (2, 2)]


def recorder_like_plotter(rig, zoom=1.0):
    import pyvista as pv

    from rigedit.render.recorder import BACKGROUND, _grid_floor
    from rigedit.render.scene import RigScene

    plotter = pv.Plotter(off_screen=True, window_size=SIZE)
    plotter.disable_anti_aliasing()
    plotter.set_background(BACKGROUND)
    RigScene(plotter, rig, show_skeleton=True)
    _grid_floor(plotter)   # opaque lines, as the recorder draws the floor
    plotter.camera.Zoom(zoom)
    return plotter


def test_frame_reader_reads_what_screenshot_reads(rig):
    from rigedit.render.video_writer import FrameReader

    plotter, other = recorder_like_plotter(rig), recorder_like_plotter(rig, zoom=2.0)
    try:
        shot, zoomed = (p.screenshot(return_img=True) for p in (plotter, other))
        reader = FrameReader(plotter, buffers=2)
        plotter.render()
        first = reader.image(reader.read())
        assert first.shape == (SIZE[1], SIZE[0], 3)
        np.testing.assert_array_equal(first, shot)   # same rows, top row first
        assert not np.array_equal(shot, shot[::-1])  # not symmetric: a flip would show
        kept = first.copy()
        plotter.camera.Zoom(2.0)                     # the mesh fills more of the frame
        plotter.render()
        second = reader.image(reader.read())
        np.testing.assert_array_equal(first, kept)   # the ring did not reuse the first buffer
        assert np.abs(second.astype(int) - kept).mean() > 0.5
        np.testing.assert_array_equal(second, zoomed)
    finally:
        plotter.close()
        other.close()


def test_skinned_normals_match_the_filter_at_rest_and_stay_close_when_posed(rig):
    import pyvista as pv

    from rigedit.render.scene import RigScene, normals_filter

    plotter = pv.Plotter(off_screen=True, window_size=SIZE)
    try:
        scene = RigScene(plotter, rig, skinned_normals=True)
        assert scene.mesh_actor.GetMapper().GetInputAlgorithm() is not scene._normals

        def recomputed():
            normals = normals_filter(pv.PolyData(scene.mesh.points.copy(),
                                                 scene.mesh.GetPolys()))
            normals.Update()
            return pv.wrap(normals.GetOutput()).point_data["Normals"]

        scene.update(rig.rest_pose())
        np.testing.assert_allclose(scene.mesh.point_data["Normals"], recomputed(), atol=1e-5)
        pose = rig.clips["bend"].sample(0.5, out=rig.rest_pose())   # bent 60 degrees
        scene.update(pose)
        cos = np.sum(scene.mesh.point_data["Normals"] * recomputed(), axis=1)
        # cosine to the recomputed normals, measured: median 1.0000, 1st percentile 0.899
        # (0.962 before heat's tighter blend, c = 4, sharpened the crease at the bend)
        assert np.median(cos) > 0.995 and np.percentile(cos, 1) > 0.85
        assert np.percentile(np.sum(scene.mesh.point_data["Normals"]
                                    * scene.rig.binding._rest_normals32, axis=1), 1) < 0.9
        # (they did turn: 1st percentile of the cosine to the rest normals measured 0.5)
    finally:
        plotter.close()
