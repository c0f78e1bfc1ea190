"""The embedding reports in rigedit.progress's protocol and stops on its Cancelled."""
import warnings

import pytest

from rigedit.embedding import embed_skeleton
from rigedit.progress import Cancelled


def test_progress_reports_fraction_and_stage_and_cancelled_stops_it(humanoid):
    seen = []

    def progress(fraction, stage):
        seen.append((fraction, stage))
        if len(seen) == 4:
            raise Cancelled

    with warnings.catch_warnings():
        warnings.simplefilter("error")   # the protocol's own form: no deprecation
        with pytest.raises(Cancelled):
            embed_skeleton(humanoid.vertices, humanoid.faces, humanoid.skeleton,
                           progress=progress)
    fractions = [f for f, _ in seen]
    assert fractions == sorted(fractions) and fractions[0] == 0.0 and len(seen) == 4
    assert {stage for _, stage in seen} == {"embed"}
