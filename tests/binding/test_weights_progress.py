"""Skin weights report in rigedit.progress's protocol, stop on its Cancelled, and still take
the older one-argument progress(fraction) (deprecated) that the editor passes today."""
import warnings

import numpy as np
import pytest

from builders import chain_skeleton, cylinder
from rigedit.binding.weights import compute_weights
from rigedit.progress import Cancelled


@pytest.mark.parametrize("method", ["heat", "idw"])
def test_fraction_and_stage_then_the_same_weights_as_without(method):
    v, f = cylinder()
    seen = []
    options = {"chunk": 64} if method == "idw" else {}   # several blocks: several calls
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        idx, w = compute_weights(v, chain_skeleton(3), method, faces=f, **options,
                                 progress=lambda fraction, stage: seen.append((fraction, stage)))
    fractions = [x for x, _ in seen]
    assert fractions == sorted(fractions) and fractions[-1] == 1.0 and len(seen) >= 2
    assert {stage for _, stage in seen} == {method}
    plain = compute_weights(v, chain_skeleton(3), method, faces=f)
    assert np.array_equal(idx, plain[0]) and np.array_equal(w, plain[1])


@pytest.mark.parametrize("method", ["heat", "idw"])
def test_cancelled_stops_the_computation(method):
    v, f = cylinder()

    def cancel(fraction, stage=None):
        if fraction > 0.3:
            raise Cancelled

    with pytest.raises(Cancelled):
        compute_weights(v, chain_skeleton(3), method, faces=f, progress=cancel,
                        **({"chunk": 64} if method == "idw" else {}))   # several blocks


def test_the_older_one_argument_progress_still_works_with_a_warning():
    v, f = cylinder()
    seen = []
    with pytest.warns(DeprecationWarning, match="progress\\(fraction, stage\\)"):
        compute_weights(v, chain_skeleton(3), "heat", faces=f, progress=seen.append)
    assert seen == sorted(seen) and seen[-1] == 1.0
