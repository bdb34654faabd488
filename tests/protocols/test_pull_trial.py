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
