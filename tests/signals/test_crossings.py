"""The force at the zero crossings of a bending angle (signals/crossings.py).

A decaying swing ``60 cos(4 pi t) exp(-t)`` deg sampled at 800 Hz crosses zero at
``t = 1/8 + k/4`` s. A force that follows the angle (largest at the swing's ends) has no peak of
its own at the crossings; the same force with a 5 ms pulse of 5 N at each crossing has one.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from tapespring.signals.crossings import force_at_crossings

T = np.arange(0.0, 2.0, 1.0 / 800.0)
ANGLE = 60.0 * np.cos(4.0 * np.pi * T) * np.exp(-T)
CROSSINGS = 0.125 + 0.25 * np.arange(8)
SWING = -0.8 + 1.0 * np.cos(4.0 * np.pi * T) * np.exp(-T)
PULSES = 5.0 * sum(np.exp(-(((T - c) / 5e-3) ** 2)) for c in CROSSINGS)


def test_crossings_are_located_between_samples() -> None:
    r = force_at_crossings(T, ANGLE, SWING)
    # Linear interpolation of a sine near its zero: error of order (omega dt)^2 dt / 24.
    np.testing.assert_allclose(r.time, CROSSINGS, atol=1e-6)
    # A quarter of the shorter flanking half-cycle; the first and last are cut by the record.
    flanks = np.r_[0.125, 0.25 * np.ones(6), T[-1] - CROSSINGS[-1]]
    np.testing.assert_allclose(r.window, 0.25 * flanks, atol=1e-6)


def test_a_pulse_at_each_crossing_stands_out() -> None:
    r = force_at_crossings(T, ANGLE, SWING + PULSES, baseline=-0.8)
    assert np.all(np.abs(r.peak_time - r.time) <= 1.0 / 800.0)
    # The pulse (5 N) over the swing's largest value in the flanking half-cycles (at most 1 N).
    assert np.all(r.ratio > 4.0), r.ratio
    np.testing.assert_allclose(r.peak, 5.0, atol=0.1)
    # Each a maximum of the deviation, at the force's own value (signed).
    assert np.all(r.local)
    np.testing.assert_array_equal(r.peak_force, np.interp(r.peak_time, T, SWING + PULSES))
    np.testing.assert_allclose(r.peak_force, 5.0 - 0.8, atol=0.1)


def test_a_force_that_follows_the_angle_has_no_peak_at_the_crossings() -> None:
    r = force_at_crossings(T, ANGLE, SWING, baseline=-0.8)
    # Within an eighth of a period of a crossing the swing is below sin(pi/4) of its envelope.
    assert np.all(r.ratio < 0.75), r.ratio
    # Its largest deviation in a window lies on the window's edge, still rising beyond it: no
    # peak at the crossing.
    assert not np.any(r.local), r.local
    assert r.as_dict()["peak_is_local_maximum"] == [False] * r.time.size


def test_start_and_end_select_the_crossings() -> None:
    r = force_at_crossings(T, ANGLE, SWING + PULSES, start=0.3, end=1.2)
    np.testing.assert_allclose(
        r.time, CROSSINGS[(CROSSINGS >= 0.3) & (CROSSINGS <= 1.2)], atol=1e-6
    )
    # The first half-cycle starts at `start`; the last ones reach beyond `end`.
    assert r.window[0] == pytest.approx(0.25 * (0.375 - 0.3), abs=1e-6)
    assert r.window[-1] == pytest.approx(0.25 * 0.25, abs=1e-6)
    assert r.baseline == pytest.approx(np.median((SWING + PULSES)[T >= 0.3]))


def test_no_crossing_gives_empty_arrays() -> None:
    r = force_at_crossings(T, np.abs(ANGLE) + 1.0, SWING)
    assert r.time.size == r.peak.size == r.ratio.size == 0
    assert r.as_dict()["time_s"] == []


@pytest.mark.parametrize(
    ("args", "kwargs", "match"),
    [
        ((T, ANGLE[:-1], SWING), {}, "one length"),
        ((T[:1], ANGLE[:1], SWING[:1]), {}, "two samples"),
        ((T, np.where(T > 1, np.nan, ANGLE), SWING), {}, "angle has non-finite"),
        ((T[::-1], ANGLE, SWING), {}, "strictly increasing"),
        ((T, ANGLE, SWING), {"fraction": 0.0}, "fraction"),
        ((T, ANGLE, SWING), {"fraction": 0.6}, "fraction"),
        ((T, ANGLE, SWING), {"start": 1.0, "end": 0.5}, "after end"),
    ],
)
def test_bad_input_is_named(args, kwargs, match) -> None:
    with pytest.raises(ValueError, match=match):
        force_at_crossings(*args, **kwargs)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(-1e3, 1e3), min_size=2, max_size=40),
    st.lists(st.floats(-1e3, 1e3), min_size=2, max_size=40),
    st.floats(0.01, 0.5),
)
def test_any_finite_record_gives_consistent_arrays(angle, force, fraction) -> None:
    n = min(len(angle), len(force))
    t = np.arange(n) * 0.01
    r = force_at_crossings(t, angle[:n], force[:n], fraction=fraction)
    assert r.time.size == r.peak.size == r.window.size == r.elsewhere.size == r.local.size
    # The peak's signed force is the record's own value there, its deviation the peak.
    j = np.searchsorted(t, r.peak_time)
    np.testing.assert_array_equal(r.peak_force, np.asarray(force[:n])[j])
    assert np.all(r.peak >= 0.0) and np.all((r.time >= t[0]) & (r.time <= t[-1]))
    assert np.all(np.abs(r.peak_time - r.time) <= np.maximum(r.window, 0.01) + 1e-12)
