"""The retarget reports its steps in rigedit.progress's protocol and stops on Cancelled."""
import numpy as np
import pytest

from rigedit.progress import Cancelled
from rigedit.rigging.retarget.pipeline import retarget


def test_the_steps_are_reported_in_order_and_change_nothing(humanoid):
    name = sorted(humanoid.clips)[0]
    seen = []
    clip = retarget(humanoid, name, humanoid,
                    progress=lambda fraction, stage: seen.append((fraction, stage)))
    assert [stage for _, stage in seen] == ["calibrate", "map", "transfer", "feet", "clip"]
    fractions = [f for f, _ in seen]
    assert fractions == sorted(fractions) and fractions[0] == 0.0 and fractions[-1] == 1.0
    plain = retarget(humanoid, name, humanoid)
    for joint, track in plain.tracks.items():
        other = clip.tracks[joint]
        assert np.array_equal(track.times, other.times)
        assert np.array_equal(track.values, other.values)


def test_a_cancel_between_the_steps_stops_the_retarget(humanoid):
    def cancel(fraction, stage):
        if stage == "transfer":
            raise Cancelled

    with pytest.raises(Cancelled):
        retarget(humanoid, sorted(humanoid.clips)[0], humanoid, progress=cancel)
