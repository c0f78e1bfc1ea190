"""File > Export video's time range end to end: the dialog's start and end give the frames of
[start, end) and the first is the pose at the start (the editor's camera held, so it is the
frame a one-frame recording at the start makes); an empty range or a start past the clip's
end is one message, nothing recorded."""
import imageio.v3 as iio
import numpy as np
import pytest

pytestmark = [pytest.mark.ui]

from rigedit.ui.record_dialog import record_video  # noqa: E402

from test_ui_file import _export_video  # noqa: E402
from ui_window_fixture import answer_file_dialog  # noqa: E402


def _fields(start, end):
    return {"width_spin": "96", "height_spin": "64", "fps_spin": "10",
            "start_spin": start, "end_spin": end}


def test_the_range_starts_at_the_pose_of_its_start(window, qtbot, tmp_path, monkeypatch):
    doc = window.document
    assert doc.clips[doc.current_clip].duration >= 1.0
    out = tmp_path / "part.gif"
    answer_file_dialog(monkeypatch, "getSaveFileName", str(out))
    _export_video(window, qtbot, _fields("0.5", "0.8"), browse=True)
    assert window.last_error is None
    part = iio.imread(out, index=None).astype(int)
    assert part.shape[:3] == (3, 64, 96)

    def one_frame(start):
        path = tmp_path / f"at-{start}.gif"
        assert record_video(doc, window.scene_view, lambda text: None, path, fps=10,
                            size=(96, 64), start=start, duration=0.1, orbit=360.0,
                            progress=False) == 1
        return iio.imread(path, index=None)[0].astype(int)

    at_start, at_zero = one_frame(0.5), one_frame(0.0)
    np.testing.assert_array_equal(part[0], at_start)
    assert np.abs(part[0] - at_zero).mean() > 0.3 * np.abs(part[-1] - part[0]).mean()


@pytest.mark.parametrize("start,end,said", [("0.6", "0.4", "expected an end after"),
                                            ("9", "10", "past the clip's end")])
def test_a_bad_range_is_one_message(window, qtbot, tmp_path, start, end, said):
    out = tmp_path / "bad.gif"
    _export_video(window, qtbot, {"path_edit": str(out), **_fields(start, end)})
    assert said in (window.last_error or "")
    assert not out.exists()
    window._last_dialog.close()
