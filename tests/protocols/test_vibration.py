"""Vibration protocol on a synthetic free decay with known damping ratio and period."""

import pytest
from tapespring.protocols import analyze_vibration
from tapespring.trials.samples import make_vibration_trial


def test_vibration_recovers_damping_ratio_and_period():
    trial = make_vibration_trial(0.00509, 0.100, seed=2)
    result = analyze_vibration(trial)
    # Bounds derived in tests/signals/test_damping.py: 4 * 8.2e-5 and 4 * 2.5e-6 s.
    assert result.fit.damping_ratio == pytest.approx(0.00509, abs=3.3e-4)
    assert result.fit.period == pytest.approx(0.100, abs=1e-5)
    assert result.release_time == pytest.approx(0.5, abs=0.02)
