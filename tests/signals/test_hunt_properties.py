"""Property tests of the signal analyses on hostile inputs: NaN, inf, constant, very short,
non-monotonic time, huge and tiny magnitudes. Each analysis gives a correct result (checked
against an independent computation or an invariant) or a ValueError/TypeError naming the
problem; never a RuntimeWarning, another exception, or a wrong number.

Regressions of a hunt: `smooth` took differences of a running sum (after one glitch of 1e17 the
later windows of unit samples averaged 0); `summarize` gave a spread of 0 for values near 1e-200
(squares underflowed) and refused values near 1e300 (squares overflowed); `extract_peaks`,
`noise_std`, `force_at_crossings`, `fit_circle`, `fit_damping`, `swing_midline` and
`max_lateral_displacement` overflowed (RuntimeWarning) on values near 1e300 or gave other peaks
on values near 1e-200; `motion_plane`, `fit_motion_frame` and `to_frame` let an IndexError, a
broadcast error or a NaN frame through; `span_samples` an OverflowError.
"""

from __future__ import annotations

import math
import statistics
import warnings
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import assume, example, given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from property_settings import examples
from tapespring import signals
from tapespring.signals.smoothing import power_of_two_scale

FLOATS = st.floats(allow_nan=True, allow_infinity=True, width=64)
ANY_ARRAY = hnp.arrays(np.float64, st.integers(0, 25), elements=FLOATS)
FINITE = st.floats(-1e6, 1e6, allow_nan=False)
# Zero, or not so small that a value of 1e300 beside it makes it a subnormal once scaled to order
# one (below 2^-1074 of the largest value no float resolves it).
MODERATE = st.one_of(st.just(0.0), st.floats(1e-6, 1e6), st.floats(-1e6, -1e-6))
# Powers of two from 2^-700 to 2^700 (the scalings are exact: results scale bit for bit).
POWERS = st.integers(-700, 700).map(lambda k: math.ldexp(1.0, k))


def _checked(call):
    """`call()` with RuntimeWarnings as errors: its result, or None if it raised a ValueError or
    TypeError with a message."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        try:
            return call()
        except (ValueError, TypeError) as exc:
            assert str(exc), f"{type(exc).__name__} without a message"
            return None


def _decay(n: int, amplitude: float, noise: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) / 200.0
    rng = np.random.default_rng(seed)
    z = amplitude * np.exp(-0.3 * t) * np.cos(2 * np.pi * 3.0 * t) + noise * rng.normal(size=n)
    return t, z


# --- any array: a result or a named refusal -------------------------------------------------


@examples(ci=12, long=300)
@given(y=ANY_ARRAY, t=ANY_ARRAY, span=st.integers(1, 30))
def test_every_analysis_gives_a_result_or_a_named_refusal(y, t, span):
    n = min(y.size, t.size)
    y, t = y[:n], t[:n]
    _checked(lambda: signals.smooth(y, span))
    _checked(lambda: signals.noise_std(y))
    _checked(lambda: signals.summarize(y))
    _checked(lambda: signals.extract_peaks(t, y))
    _checked(lambda: signals.fit_damping(t, y, (0.1, 10.0)))
    _checked(lambda: signals.force_at_crossings(t, y, y[::-1]))
    _checked(lambda: signals.max_lateral_displacement(y))
    _checked(lambda: signals.swing_midline(y, 1.0))
    _checked(lambda: signals.release_index(y, 1.0))
    _checked(lambda: signals.equilibrium_value(t, y))
    _checked(lambda: signals.analyze_pull_test(t, y, span=span))
    _checked(lambda: signals.fit_circle(np.column_stack((t, y))))
    m = n - n % 3
    _checked(lambda: signals.bending_angle(t[:m].reshape(-1, 3), y[:m].reshape(-1, 3)))
    peaks = _checked(lambda: signals.extract_peaks(t, y, None))
    if peaks is not None:
        _checked(lambda: signals.detect_phases(peaks))


# --- smooth ----------------------------------------------------------------------------------


def _smooth_directly(y: np.ndarray, span: int) -> np.ndarray:
    """MATLAB's smooth, each window's mean summed exactly (fractions)."""
    n = y.size
    h = signals.effective_span(span, n) // 2
    out = np.empty(n)
    for i in range(n):
        k = min(i, n - 1 - i, h)
        window = [Fraction(v) for v in y[i - k : i + k + 1] if np.isfinite(v)]
        out[i] = float(sum(window) / len(window)) if window else np.nan
    return out


@examples(ci=12, long=300)
@given(
    y=hnp.arrays(np.float64, st.integers(1, 40), elements=MODERATE),
    glitch=st.floats(-1e300, 1e300),
    where=st.integers(0, 39),
    span=st.integers(1, 45),
)
@example(y=np.array([4096.0, 0, 0, 0, 0, 0]), glitch=2.225073858507203e-309, where=3, span=3)
def test_smooth_is_each_windows_own_mean_whatever_a_glitch(y, glitch, where, span):
    """A glitch of any size disturbs the windows that hold it, and no other."""
    y = y.copy()
    y[where % y.size] = glitch
    got = _checked(lambda: signals.smooth(y, span))
    want = _smooth_directly(y, span)
    # Each window's own samples only: the rounding is relative to the largest in the window,
    # but for subnormal samples, which smooth divides by the record's power of two (4096 for
    # the long profile's [4096, 0, 0, 2.2e-309, 0, 0]) and so keeps to a few ulps of that
    # power times the smallest subnormal (9.4e-321 off there).
    scale = np.array([np.max(np.abs(y[max(0, i - span) : i + span + 1])) for i in range(y.size)])
    subnormal_ulp = 4.0 * 5e-324 * power_of_two_scale(y)
    assert np.all(np.abs(got - want) <= 1e-12 * scale + subnormal_ulp)


def test_smooth_after_a_glitch_keeps_the_small_samples():
    y = np.array([1e17, 0, 0, 0, 1, 1, 1, 1, 1, 1.0])
    np.testing.assert_allclose(signals.smooth(y, 3)[3:], [1 / 3, 2 / 3, 1, 1, 1, 1, 1])


@examples(ci=12, long=200)
@given(y=hnp.arrays(np.float64, st.integers(1, 40), elements=MODERATE), span=st.integers(1, 45))
def test_smooth_of_values_near_the_float_limits_scales_exactly(y, span):
    for c in (2.0**1000, 2.0**-1000):
        np.testing.assert_array_equal(signals.smooth(y * c, span), signals.smooth(y, span) * c)


# --- noise, statistics --------------------------------------------------------------------------


@examples(ci=12, long=200)
@given(y=hnp.arrays(np.float64, st.integers(3, 40), elements=FINITE), c=POWERS)
# Values near the float limit, which the drawn ones (at most 1e6 * 2^700) do not reach: the
# differences overflowed before the values were scaled.
@example(y=np.array([0.75, -0.75, 0.75, -0.5, 0.25]), c=2.0**1023)
def test_noise_std_scales_with_the_signal(y, c):
    assume(np.all(np.isfinite(y * c)) and np.all(np.abs(y[y != 0] * c) >= 2.0**-1000))
    assert signals.noise_std(y * c) == signals.noise_std(y) * c


@examples(ci=12, long=300)
@given(
    x=hnp.arrays(np.float64, st.integers(1, 12), elements=st.floats(-1e3, 1e3)),
    exponent=st.integers(-300, 300),
)
def test_summarize_matches_exact_statistics_at_any_magnitude(x, exponent):
    """Python's statistics work in exact fractions: the oracle."""
    values = x * 10.0**exponent
    assume(np.all(np.isfinite(values)) and np.all((values == 0) | (np.abs(values) > 1e-290)))
    s = signals.summarize(values)
    data = values.tolist()
    assert s.mean == pytest.approx(statistics.fmean(data), rel=1e-12, abs=0)
    if len(data) >= 2:
        spread = 1e-12 * float(np.max(np.abs(values)))  # the rounding of the mean
        assert s.std == pytest.approx(statistics.stdev(data), rel=1e-9, abs=spread)
    assert s.max_diff == max(data) - min(data)
    assert s.count == len(data)


def test_summarize_of_tiny_values_has_their_spread():
    s = signals.summarize([1e-200, 2e-200, 3e-200])
    assert s.std == pytest.approx(1e-200, rel=1e-12)
    assert s.cv == pytest.approx(0.5, rel=1e-12)


# --- peaks, damping ----------------------------------------------------------------------------


@examples(ci=8, long=120)
@given(seed=st.integers(0, 2**32 - 1), c=POWERS, noise=st.sampled_from([0.0, 0.01, 0.05]))
def test_peaks_of_a_scaled_signal_are_the_scaled_peaks(seed, c, noise):
    t, z = _decay(600, 1.0, noise, seed)
    a = signals.extract_peaks(t, z, None)
    b = _checked(lambda: signals.extract_peaks(t, z * c, None))
    assert b is not None
    for ea, eb in ((a.maxima, b.maxima), (a.minima, b.minima)):
        np.testing.assert_array_equal(eb.time, ea.time)
        np.testing.assert_array_equal(eb.value, ea.value * c)
    assert b.noise == a.noise * c


@examples(ci=6, long=80)
@given(seed=st.integers(0, 2**32 - 1), exponent=st.integers(-250, 250))
def test_a_damping_fit_does_not_depend_on_the_unit_of_z(seed, exponent):
    t, z = _decay(1200, 1.0, 0.002, seed)
    c = 10.0**exponent
    a = signals.fit_damping(t, z, (0.05, 1.0))
    b = _checked(lambda: signals.fit_damping(t, z * c, (0.05 * c, 1.0 * c)))
    assert b is not None
    assert b.damping_ratio == pytest.approx(a.damping_ratio, rel=1e-6)
    assert b.period == pytest.approx(a.period, rel=1e-9)
    assert b.amplitude == pytest.approx(a.amplitude * c, rel=1e-6)


# --- crossings ----------------------------------------------------------------------------------


@examples(ci=12, long=300)
@given(
    a=hnp.arrays(np.float64, st.integers(2, 40), elements=MODERATE),
    c=st.floats(1e-290, 1e290),
)
@example(a=np.array([1.5, -1.5, 0.5]), c=1e308)  # the interpolation's difference overflowed
def test_crossings_are_the_interpolated_sign_changes_at_any_magnitude(a, c):
    t = np.arange(a.size) * 0.01
    got = _checked(lambda: signals.force_at_crossings(t, a * c, np.ones_like(a)))
    assert got is not None
    want = []
    for i in range(a.size - 1):
        if (a[i] >= 0) != (a[i + 1] >= 0):
            w = Fraction(a[i]) / (Fraction(a[i]) - Fraction(a[i + 1]))
            want.append(float(Fraction(t[i]) + w * (Fraction(t[i + 1]) - Fraction(t[i]))))
    np.testing.assert_allclose(got.time, want, rtol=1e-12, atol=1e-15)


@examples(ci=8, long=200)
@given(
    f=hnp.arrays(np.float64, 40, elements=st.floats(-1e3, 1e3)),
    c=POWERS,
)
@example(f=np.linspace(1.5, 1.9, 40), c=2.0**1023)  # the baseline's median overflowed
def test_crossing_peaks_scale_with_the_force(f, c):
    t = np.arange(40) * 0.01
    angle = np.cos(2 * np.pi * 2.0 * t)
    a = signals.force_at_crossings(t, angle, f)
    assume(np.all(np.isfinite(f * c)) and np.all((f == 0) | (np.abs(f * c) >= 2.0**-1000)))
    b = _checked(lambda: signals.force_at_crossings(t, angle, f * c))
    np.testing.assert_array_equal(b.peak, a.peak * c)
    np.testing.assert_array_equal(b.elsewhere, a.elsewhere * c)


def test_a_non_finite_crossing_baseline_is_named():
    t = np.arange(10) * 0.1
    with pytest.raises(ValueError, match="baseline must be a finite force"):
        signals.force_at_crossings(t, np.cos(t * 5), np.ones(10), baseline=math.nan)


# --- circle, lateral excursion, midline ---------------------------------------------------------


@examples(ci=12, long=300)
@given(
    exponent=st.integers(-250, 250),
    centre=st.tuples(st.floats(-10, 10), st.floats(-10, 10)),
    arc=st.floats(0.5, 2 * np.pi),
    start=st.floats(0, 2 * np.pi),
)
def test_a_circle_of_any_size_is_found(exponent, centre, arc, start):
    r = 10.0**exponent
    phi = start + np.linspace(0.0, arc, 9)
    points = np.column_stack((centre[0] * r + r * np.cos(phi), centre[1] * r + r * np.sin(phi)))
    fit = _checked(lambda: signals.fit_circle(points))
    assert fit is not None
    assert fit.radius == pytest.approx(r, rel=1e-6)
    np.testing.assert_allclose(fit.center, np.array(centre) * r, rtol=1e-6, atol=1e-6 * r)


@examples(ci=12, long=300)
@given(y=hnp.arrays(np.float64, st.integers(1, 30), elements=FINITE), c=POWERS)
@example(y=np.full(20, 1.5), c=2.0**1023)  # the reference's median overflowed
def test_lateral_excursion_and_midline_scale_with_the_signal(y, c):
    assume(np.all(np.isfinite(y * c)) and np.all((y == 0) | (np.abs(y * c) >= 2.0**-1000)))
    assert signals.max_lateral_displacement(y * c) == signals.max_lateral_displacement(y) * c
    assert signals.swing_midline(y * c, 0.5 * c) == signals.swing_midline(y, 0.5) * c


def test_the_midline_of_a_swing_near_the_float_limit_scales_exactly():
    # The swing's range (its prominence bound) overflowed before the values were scaled.
    y = np.array([1.9, -1.7, 1.9, -1.7, 1.9, -1.7, 1.9])
    c = 2.0**1023
    assert signals.swing_midline(y * c, 0.5 * c) == signals.swing_midline(y, 0.5) * c


def test_an_excursion_beyond_the_floats_is_named():
    with pytest.raises(ValueError, match="beyond the floating-point range"):
        signals.max_lateral_displacement(np.array([1.7e308, -1.7e308]))


# --- frame, spans -----------------------------------------------------------------------------


@examples(ci=12, long=200)
@given(
    rows=st.integers(0, 6),
    cols=st.integers(1, 4),
    other=st.integers(0, 6),
)
def test_markers_of_the_wrong_shape_are_named(rows, cols, other):
    origin = np.zeros((rows, cols))
    moving = np.ones((other, 3))
    assume(not (cols == 3 and rows == other))
    with pytest.raises(ValueError, match="must have shape"):
        signals.motion_plane(origin, moving)
    with pytest.raises(ValueError, match="must have shape"):
        signals.fit_motion_frame(origin, moving)


def _turning(n: int = 40) -> tuple[np.ndarray, np.ndarray]:
    phi = np.linspace(0.0, 1.0, n)
    return np.zeros((n, 3)), np.column_stack((np.cos(phi), np.zeros(n), np.sin(phi)))


@pytest.mark.parametrize(
    "deployed", [np.ones(5, bool), np.arange(40) % 2, np.ones((40, 1), bool), [1.5] * 40]
)
def test_a_deployed_mask_that_is_not_one_boolean_per_sample_is_named(deployed):
    origin, moving = _turning()
    with pytest.raises(ValueError, match="deployed must be an array of 40 booleans"):
        signals.fit_motion_frame(origin, moving, deployed=deployed)


def test_a_deployed_state_without_complete_samples_is_named_not_a_nan_frame():
    origin, moving = _turning()
    moving[-4:] = np.nan
    with pytest.raises(ValueError, match="no complete sample"):
        signals.fit_motion_frame(origin, moving)


@examples(ci=12, long=200)
@given(shape=st.tuples(st.integers(0, 4), st.integers(0, 4)), frame=st.integers(1, 4))
def test_to_frame_names_a_wrong_shape(shape, frame):
    assume(shape[1] != 3 or frame != 3)
    with pytest.raises(ValueError, match="must have shape"):
        signals.to_frame(np.eye(frame), np.zeros(shape))


@pytest.mark.parametrize(("duration", "rate"), [(1e300, 1e300), (1e200, 1e200), (1e308, 10.0)])
def test_a_span_beyond_any_sample_count_is_named(duration, rate):
    with pytest.raises(ValueError, match="beyond any number of samples"):
        signals.span_samples(np.float64(duration), np.float64(rate))


@examples(ci=12, long=300)
@given(values=hnp.arrays(np.float64, st.integers(0, 10), elements=FLOATS))
def test_power_of_two_scale_brings_the_values_below_two(values):
    s = power_of_two_scale(values)
    finite = values[np.isfinite(values)]
    assert s > 0 and math.frexp(s)[0] == 0.5
    if finite.size and np.any(finite != 0):
        assert 1.0 <= np.max(np.abs(finite)) / s < 2.0
