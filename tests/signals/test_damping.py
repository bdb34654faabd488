"""Damped-oscillator fit on free decays with known damping ratio and period."""

import numpy as np
import pytest
from tapespring.signals import fit_damping, select_window_peaks
from tapespring.trials.samples import vibration_displacement

RATE = 800.0
SIGMA = 0.05e-3  # m, marker precision (paper Sec. 3.3)
WINDOW = (0.4e-3, 4.0e-3)


def _decay(eps, period, sigma=0.0, seed=0, duration=10.0):
    t = np.arange(0, duration, 1 / RATE)
    z = vibration_displacement(t, eps, period, -8e-3, 0.5)
    return t, z + np.random.default_rng(seed).normal(0, sigma, t.size)


@pytest.mark.parametrize(("eps", "period"), [(0.00509, 0.100), (0.01, 0.110), (0.003, 0.08)])
def test_fit_recovers_damping_and_period_without_noise(eps, period):
    t, z = _decay(eps, period)
    fit = fit_damping(t, z, WINDOW, t_start=0.5)
    # Exact model: residual errors come from the sampled-peak refinement only.
    assert fit.damping_ratio == pytest.approx(eps, rel=1e-4)
    assert fit.period == pytest.approx(period, rel=1e-5)
    assert fit.success and fit.r_squared > 1 - 1e-8


def test_fit_recovers_damping_and_period_at_marker_noise():
    eps, period = 0.00509, 0.100
    # Bounds for sigma = 0.05 mm. Each refined peak value has an error <= sigma
    # (relative <= sigma / 0.4 mm = 0.125 at the window's low end); the decay rate
    # a = eps omega0 comes from ~n = 2 * 7 s / 0.1 s = 140 peaks spread over
    # D = 7 s: std(a) <= 0.125 / sqrt(n D^2 / 12) = 5.1e-3 1/s, i.e.
    # std(eps) <= 5.1e-3 / 62.8 = 8.2e-5. Peak times are off by less than half a
    # sample (0.625 ms): std(period) <= 2 * 0.625e-3 / sqrt(n * n^2 / 12) = 2.5e-6 s.
    # Tolerance: 4 standard deviations.
    n_peaks = 2 * 7.0 / period
    std_a = (SIGMA / WINDOW[0]) / np.sqrt(n_peaks * 7.0**2 / 12)
    std_eps = std_a / (2 * np.pi / period)
    std_period = 2 * 0.5 / RATE / np.sqrt(n_peaks**3 / 12)
    for seed in range(3):
        t, z = _decay(eps, period, SIGMA, seed)
        fit = fit_damping(t, z, WINDOW, t_start=0.5)
        assert fit.damping_ratio == pytest.approx(eps, abs=4 * std_eps)
        assert fit.period == pytest.approx(period, abs=4 * std_period)
        # The reported standard errors are of the same order as the bounds.
        assert 0 < fit.damping_ratio_std < 4 * std_eps
        assert 0 < fit.period_std < 4 * std_period


def test_period_and_pulsation_satisfy_eq_6():
    t, z = _decay(0.02, 0.1)
    fit = fit_damping(t, z, WINDOW)
    expected = 2 * np.pi / (fit.omega0 * np.sqrt(1 - fit.damping_ratio**2))
    assert fit.period == pytest.approx(expected, rel=1e-12)


def test_only_peaks_inside_the_window_are_used():
    t, z = _decay(0.00509, 0.1, SIGMA)
    fit = fit_damping(t, z, WINDOW, t_start=0.5)
    assert np.all(np.abs(fit.peak_value) >= WINDOW[0])
    assert np.all(np.abs(fit.peak_value) <= WINDOW[1])
    time, value = select_window_peaks(t, z, WINDOW, t_start=0.5)
    # Peaks alternate in sign and every in-window peak of the true decay is found:
    # the envelope 8 mm exp(-a s) crosses 4 mm at s = ln(2)/a and 0.4 mm at
    # s = ln(20)/a; one peak per half period in between (+-1 at each end where
    # noise decides on a peak at the window's edge).
    assert np.all(np.sign(value[1:]) == -np.sign(value[:-1]))
    a = 0.00509 * 2 * np.pi / 0.1
    expected = 2 * (np.log(20) - np.log(2)) / a / 0.1
    assert abs(time.size - expected) <= 2


def test_too_few_peaks_in_the_window_raise():
    t, z = _decay(0.00509, 0.1, duration=1.0)  # amplitude never below 4 mm... mostly
    with pytest.raises(ValueError, match="at least 3 are needed"):
        fit_damping(t, z, (0.1e-3, 0.2e-3))
