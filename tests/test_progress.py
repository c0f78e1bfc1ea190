"""rigedit.progress: the one protocol progress(fraction, stage), its helpers, and the older
one-argument form kept (deprecated) while callers move over."""
import pytest

from rigedit.progress import Cancelled, adapt, null_progress, scaled, takes_stage


def test_adapt_passes_the_protocol_through_and_labels_calls_without_a_stage():
    seen = []
    progress = adapt(lambda fraction, stage: seen.append((fraction, stage)), "heat")
    progress(0.25)
    progress(0.5, "solve")
    progress(None)
    assert seen == [(0.25, "heat"), (0.5, "solve"), (None, "heat")]
    assert adapt(None) is null_progress


def test_a_one_argument_callable_still_works_with_a_deprecation_warning():
    seen = []
    with pytest.warns(DeprecationWarning, match="progress\\(fraction, stage\\)"):
        progress = adapt(seen.append, "heat")
    progress(0.5, "heat")
    progress(1.0)
    assert seen == [0.5, 1.0]


def test_a_cancel_raised_by_the_callable_goes_through():
    def cancel(fraction, stage=None):
        raise Cancelled

    with pytest.raises(Cancelled):
        adapt(cancel, "embed")(0.1)
    with pytest.raises(Cancelled):
        scaled(cancel, 0.0, 0.5)(0.2, "x")


def test_takes_stage_tells_the_two_forms_apart():
    assert takes_stage(lambda fraction, stage: None)
    assert takes_stage(lambda fraction, stage=None: None)
    assert takes_stage(lambda *args: None)
    assert not takes_stage(lambda fraction: None)
    assert not takes_stage([].append)


def test_scaled_maps_a_step_onto_its_band_and_keeps_a_fixed_stage():
    seen = []
    step = scaled(lambda fraction, stage: seen.append((fraction, stage)), 0.5, 1.0, "weights")
    step(0.0, "heat")
    step(0.5)
    step(2.0)
    assert seen == [(0.5, "weights"), (0.75, "weights"), (1.0, "weights")]
    assert scaled(None, 0, 1) is null_progress
