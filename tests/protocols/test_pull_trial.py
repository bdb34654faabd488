"""Quasi-static pull protocol on a synthetic trial with a known maximum."""

import pytest
from tapespring.protocols import analyze_pull_trial
from tapespring.trials.samples import MARKER_SD, make_pull_test_trial


def test_pull_trial_recovers_maximum_force_and_displacement():
    result = analyze_pull_trial(make_pull_test_trial(seed=3))
    # tests/signals/test_pull_maximum.py bounds, plus the displacement noise (0.05 mm at
    # 800 Hz interpolated at the force instants).
    assert result.test.max_force == pytest.approx(9.8, abs=0.26)
    assert result.test.displacement_at_max == pytest.approx(10.8e-3, abs=0.3e-3 + 5 * MARKER_SD)


def test_a_smoothing_span_longer_than_the_record_is_refused():
    # smooth() would shrink the window to the whole record and report its mean as the maximum.
    from tapespring.trials import TrialError

    trial = make_pull_test_trial(seed=3)
    n = trial.force_plate(0).force.shape[0]
    rate = trial.force_plate(0).rate
    message = f"span \\({n + 1} samples\\) is longer than the force record \\({n} samples\\)"
    with pytest.raises(TrialError, match=f"{message}.*force plate at {rate:g} Hz"):
        analyze_pull_trial(trial, span=n + 1)
    with pytest.raises(TrialError, match="is longer than the force record"):
        analyze_pull_trial(trial, span_time=1e3)
