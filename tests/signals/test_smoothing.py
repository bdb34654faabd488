"""Signal primitives: MATLAB smooth and noise level."""

import numpy as np
import pytest
from tapespring.signals import effective_span, noise_std, smooth


def _smooth_by_definition(y, span):
    """MATLAB smooth, written as its documentation states it, one sample at a time."""
    n = len(y)
    width = min(span, n)
    if width % 2 == 0:
        width -= 1
    out = []
    for i in range(n):
        half = min(i, n - 1 - i, width // 2)
        window = [v for v in y[i - half : i + half + 1] if not np.isnan(v)]
        out.append(sum(window) / len(window) if window else np.nan)
    return np.array(out)


def test_smooth_hand_checked_span_5():
    # y = k^2: ends shrink (1), (1+4+9)/3, then full windows of 5.
    y = np.array([1.0, 4, 9, 16, 25, 36, 49])
    expected = [1.0, 14 / 3, 55 / 5, 90 / 5, 135 / 5, 110 / 3, 49.0]
    np.testing.assert_allclose(smooth(y, 5), expected, rtol=1e-15)


def test_smooth_even_span_is_reduced_by_one():
    y = np.array([1.0, 4, 9, 16, 25, 36, 49])
    np.testing.assert_array_equal(smooth(y, 4), smooth(y, 3))
    np.testing.assert_allclose(smooth(y, 3)[1:-1], [14 / 3, 29 / 3, 50 / 3, 77 / 3, 110 / 3])


def test_smooth_span_longer_than_signal_is_clipped():
    y = np.array([3.0, 1.0, 2.0, 7.0])
    # span 101 -> 4 -> odd 3: [3, (3+1+2)/3, (1+2+7)/3, 7]
    np.testing.assert_allclose(smooth(y, 101), [3.0, 2.0, 10 / 3, 7.0])


@pytest.mark.parametrize(
    ("span", "n", "used"),
    [(5, 7, 5), (4, 7, 3), (100, 4000, 99), (101, 4, 3), (101, 5, 5), (2, 1, 1), (3, 0, 1)],
)
def test_effective_span_is_the_odd_span_smooth_uses(span, n, used):
    assert effective_span(span, n) == used
    y = np.random.default_rng(n).normal(size=n)
    np.testing.assert_array_equal(smooth(y, span), smooth(y, used))


def test_smooth_span_one_is_identity():
    y = np.random.default_rng(0).normal(size=20)
    np.testing.assert_array_equal(smooth(y, 1), y)


def test_smooth_ignores_nan_like_matlab():
    y = np.array([1.0, np.nan, 3.0, 5.0, np.nan])
    np.testing.assert_allclose(smooth(y, 3), [1.0, 2.0, 4.0, 4.0, np.nan])


@pytest.mark.parametrize("span", [2, 5, 25, 101, 1000])
def test_smooth_matches_its_definition_on_random_data(span):
    y = np.random.default_rng(span).normal(size=301)
    y[[5, 77, 78, 200]] = np.nan
    np.testing.assert_allclose(smooth(y, span), _smooth_by_definition(y, span), rtol=1e-12)


def test_smooth_rejects_bad_span():
    with pytest.raises(ValueError, match="span"):
        smooth(np.ones(5), 0)


def test_noise_std_recovers_white_noise_on_a_smooth_signal():
    n, sigma = 8000, 0.05e-3
    t = np.arange(n) / 800.0
    y = 4e-3 * np.cos(2 * np.pi * 10 * t) + np.random.default_rng(1).normal(0, sigma, n)
    # MAD-based estimate: relative standard error ~ 1.1 / sqrt(n / 3) for 2nd
    # differences (correlated over 3 samples) = 0.021; 5 of them = 0.11. The signal
    # adds (2 pi 10)^2 4e-3 / 800^2 = 2.5e-5 m to the 1.2e-4 m of the differences.
    assert noise_std(y) == pytest.approx(sigma, rel=0.11 + 0.05)
