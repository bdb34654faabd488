"""Deployment phases from the peaks of the bending angle."""

import numpy as np
import pytest
from tapespring.signals import (
    bending_angle,
    detect_phases,
    equilibrium_value,
    extract_peaks,
    release_index,
)
from tapespring.trials.samples import make_deployment_trial


def _peaks(trial):
    theta = bending_angle(trial.marker("M1"), trial.marker("M2"))
    theta -= equilibrium_value(trial.time, theta)
    i = release_index(theta, np.deg2rad(2))
    return extract_peaks(trial.time[i:], theta[i:], None, t_ref=trial.time[i])


@pytest.mark.parametrize("sense", ["opposite", "equal"])
def test_phase_transitions_are_found_at_the_known_peaks(sense):
    for seed in range(6):
        trial, truth = make_deployment_trial(sense, seed=seed, spread=0.03)
        phases = detect_phases(_peaks(trial))
        assert phases.phase_ii_index == truth.phase_ii_index
        assert phases.phase_iii_index == truth.phase_iii_index
        # Boundary instants are those of the starting peaks (peak-time accuracy).
        assert phases.phase_ii_start == pytest.approx(
            truth.peak_time[truth.phase_ii_index], abs=0.01
        )
        assert phases.phase_iii_start == pytest.approx(
            truth.peak_time[truth.phase_iii_index], abs=0.01
        )


def test_symmetric_decay_is_all_phase_iii():
    t = np.arange(0, 5, 1 / 800)
    y = np.exp(-0.3 * t) * np.cos(2 * np.pi * 5 * t)
    phases = detect_phases(extract_peaks(t, y, None))
    assert phases.phase_iii_index == 0
    assert phases.phase_ii_index is None
    labels = phases.phase_at(np.array([phases.peak_time[0], 4.0]))
    np.testing.assert_array_equal(labels, [3, 3])


def test_phase_at_labels_instants():
    trial, truth = make_deployment_trial("opposite")
    phases = detect_phases(_peaks(trial))
    labels = phases.phase_at(np.array([0.4, phases.phase_ii_start, phases.phase_iii_start + 1]))
    np.testing.assert_array_equal(labels, [1, 2, 3])


@pytest.mark.filterwarnings("error")
def test_peaks_at_one_instant_are_a_value_error_not_a_log_of_zero():
    # An angle measured in the wrong plane jumps by 180 deg: a maximum and a minimum on one
    # instant, a half-cycle of no duration whose log-duration was -inf (numpy warnings, NaN).
    from tapespring.signals.peaks import Extrema, Peaks

    def extrema(time, value):
        time = np.asarray(time, dtype=float)
        return Extrema(time, np.asarray(value, dtype=float), np.diff(time, prepend=0.0), time * 0)

    peaks = Peaks(
        extrema([0.1, 0.3, 0.5], [1, 0.5, 0.4]),
        extrema([0.2, 0.3, 0.6], [-1, -2, -0.3]),
        0.01,
        0.001,
        0.0,
    )
    with pytest.raises(ValueError, match=r"successive peaks at 0\.3 and 0\.3 s are not in"):
        detect_phases(peaks)
