"""Quasi-static pull test: maximum force before buckling and its displacement."""

import numpy as np
import pytest
from tapespring.signals import analyze_pull_test

RATE = 4000.0  # Hz: span 101 = 25 ms, as in the paper
SPEED = 1e-3  # m/s
F_MAX, D_MAX = 9.8, 10.8e-3  # paper Table 2


def _ramp(sigma=0.0, seed=0):
    t = np.arange(0, 16.0, 1 / RATE)
    d = SPEED * t
    f = np.where(d <= D_MAX, F_MAX * d / D_MAX, 0.35 * F_MAX)
    return d, f + np.random.default_rng(seed).normal(0, sigma, t.size)


def test_noise_free_maximum_is_the_window_mean_ending_at_the_drop():
    d, f = _ramp()
    test = analyze_pull_test(d, f, span=101)
    # The smoothed force peaks where the 101-sample window ends at the last sample
    # before the drop: 50 samples earlier, and the mean of a linear ramp over the
    # window is its centre value.
    i_drop = np.flatnonzero(d <= D_MAX)[-1]
    assert test.index_at_max == i_drop - 50
    assert test.max_force == pytest.approx(f[i_drop - 50], rel=1e-12)
    assert test.displacement_at_max == pytest.approx(d[i_drop - 50])
    assert test.buckled


def test_noisy_maximum_within_derived_tolerance():
    sigma = 0.5  # N, noise of a 125 N range plate
    # Smoothed noise: sigma / sqrt(101) = 0.05 N; its maximum over the ~20 window
    # widths near the top adds at most ~3.5 of them; the ramp slope
    # F_MAX / D_MAX = 907 N/m turns 0.05 N into 55 um. Tolerance: force 5 * 0.05 N
    # + the window bias (50 samples of ramp = 0.011 N); displacement 0.25 N / slope
    # + the 50-sample shift (12.5 um).
    s = sigma / np.sqrt(101)
    slope = F_MAX / D_MAX
    for seed in range(3):
        test = analyze_pull_test(*_ramp(sigma, seed), span=101)
        assert test.max_force == pytest.approx(F_MAX, abs=5 * s + slope * 50 * SPEED / RATE)
        assert test.displacement_at_max == pytest.approx(
            D_MAX, abs=5 * s / slope + 50 * SPEED / RATE
        )
        assert test.buckled


def test_monotonic_force_is_not_buckled():
    d = np.linspace(0, 0.01, 500)
    assert not analyze_pull_test(d, 100 * d, span=11).buckled


def test_mismatched_lengths_raise():
    with pytest.raises(ValueError, match="equal length"):
        analyze_pull_test(np.zeros(5), np.zeros(6))


def test_a_span_longer_than_the_record_is_refused_not_shrunk():
    # smooth() limits its window to the record: a 101-sample span on 60 samples would smooth
    # over 59 and report a mean over the record as the maximum force.
    d = np.linspace(0.0, 0.01, 60)
    with pytest.raises(ValueError, match=r"span \(101 samples\) is longer than the force record "):
        analyze_pull_test(d, 100 * d, span=101)
    with pytest.raises(ValueError, match=r"force record \(60 samples\)"):
        analyze_pull_test(d, 100 * d, span=61)


def test_a_span_of_the_whole_record_is_used():
    d = np.linspace(0.0, 0.01, 61)
    test = analyze_pull_test(d, 100 * d, span=61)
    assert test.span == 61
    # The one complete window is centred on the record; the ends keep their raw samples.
    assert test.force_smoothed[30] == pytest.approx(np.mean(100 * d))


def test_an_even_span_is_recorded_as_the_odd_span_used():
    # smooth() reduces an even span by one: span 100 smooths over 99 samples, and the result
    # said 100.
    d, f = _ramp()
    test = analyze_pull_test(d, f, span=100)
    assert test.span == 99
    np.testing.assert_array_equal(
        test.force_smoothed, analyze_pull_test(d, f, span=99).force_smoothed
    )


def test_a_raw_end_sample_above_the_peak_is_not_the_maximum():
    # MATLAB's smooth shrinks its window at the record's ends down to the raw samples: a last
    # sample above the smoothed peak (noise on the force after buckling) read as the maximum,
    # at the record's end. The maximum is taken where the window is complete.
    d, f = _ramp()
    f[-1] = 1.5 * F_MAX
    test = analyze_pull_test(d, f, span=101)
    i_drop = np.flatnonzero(d <= D_MAX)[-1]
    assert test.index_at_max == i_drop - 50
    assert test.buckled
