"""The playback clock: elapsed wall time -> clip time, speed, loop, skip-ahead, one-shot end."""
import pytest

from rigedit.animation.playback import PlaybackClock, snap_to_frame


def test_time_follows_elapsed_wall_time_not_calls():
    c = PlaybackClock(duration=10)
    c.play(now=100.0)
    assert c.time(100.5) == pytest.approx(0.5)
    # a slow frame: nothing sampled for 2 s, the clip has moved on by 2 s
    assert c.time(102.5) == pytest.approx(2.5)


def test_speed_and_pause_resume():
    c = PlaybackClock(duration=10, speed=2.0)
    c.play(0.0)
    c.pause(1.0)
    assert c.time(50.0) == pytest.approx(2.0)
    c.play(50.0)
    assert c.time(50.5) == pytest.approx(3.0)
    c.set_speed(0.5, 50.5)
    assert c.time(51.5) == pytest.approx(3.5)


def test_loop_wraps_and_one_shot_stops_at_the_end():
    c = PlaybackClock(duration=2, loop=True)
    c.play(0.0)
    assert c.time(5.0) == pytest.approx(1.0)
    c = PlaybackClock(duration=2, loop=False)
    c.play(0.0)
    assert c.time(5.0) == pytest.approx(2.0)
    assert not c.playing
    c.play(10.0)                     # play again from the start
    assert c.time(10.25) == pytest.approx(0.25)


def test_backwards_loop_and_seek_and_stop():
    c = PlaybackClock(duration=2, speed=-1)
    c.seek(0.5, 0.0)
    c.play(0.0)
    assert c.time(1.0) == pytest.approx(1.5)
    c.seek(1.0, 3.0)
    assert c.time(3.25) == pytest.approx(0.75)
    c.stop()
    assert c.time(99) == 0.0 and not c.playing


def test_snap_to_frame():
    assert snap_to_frame(0.51, 24) == pytest.approx(12 / 24)
