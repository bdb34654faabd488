"""Property tests of the trial data model on generated trials: the CSV files give back what was
written (gaps included), `crop` keeps exactly the samples asked for, `fill_gaps` fills the short
interior gaps only and never moves a measured sample."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from property_settings import examples
from tapespring.trials import ForcePlate, Metadata, Trial, TrialError, read_csv, write_csv

COORD = st.floats(-5.0, 5.0, allow_nan=False)


@st.composite
def trials(draw: st.DrawFn) -> Trial:
    """A trial of 3 to 40 samples at 100 to 1000 Hz, 1 or 2 markers with NaN gaps, maybe a
    force plate at twice the rate."""
    n = draw(st.integers(3, 40))
    rate = draw(st.sampled_from([100.0, 250.0, 800.0, 1000.0]))
    time = np.arange(n) / rate
    markers = {}
    for name in draw(st.sampled_from([["m1"], ["m1", "m2"]])):
        xyz = draw(hnp.arrays(np.float64, (n, 3), elements=COORD))
        missing = draw(hnp.arrays(np.bool_, n))
        missing[0] = False  # at least one measured sample
        xyz[missing] = np.nan
        markers[name] = xyz
    plates = ()
    if draw(st.booleans()):
        m = 2 * n
        plates = (
            ForcePlate(
                np.arange(m) / (2 * rate),
                draw(hnp.arrays(np.float64, (m, 3), elements=st.floats(-100, 100))),
                draw(hnp.arrays(np.float64, (m, 3), elements=st.floats(-10, 10))),
            ),
        )
    return Trial(time, markers, plates, Metadata(name="generated"))


@examples(ci=10, long=200)
@given(trial=trials(), unit=st.sampled_from(["m", "cm", "mm"]))
def test_a_trial_written_to_csv_reads_back(tmp_path_factory, trial, unit):
    path = write_csv(trial, tmp_path_factory.mktemp("csv") / "t.csv", length_unit=unit)
    back = read_csv(path)
    # The files hold 10 significant digits (``%.10g``).
    np.testing.assert_allclose(back.time, trial.time, rtol=1e-9, atol=1e-12)
    assert set(back.markers) == set(trial.markers)
    for name, xyz in trial.markers.items():
        np.testing.assert_allclose(back.markers[name], xyz, rtol=1e-9, atol=1e-12)
    assert len(back.force_plates) == len(trial.force_plates)
    for a, b in zip(trial.force_plates, back.force_plates, strict=True):
        np.testing.assert_allclose(b.force, a.force, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(b.moment, a.moment, rtol=1e-9, atol=1e-12)


@examples(ci=12, long=300)
@given(
    trial=trials(),
    start=st.one_of(st.none(), st.floats(-1.0, 1.0), st.just(math.nan)),
    stop=st.one_of(st.none(), st.floats(-1.0, 1.0), st.just(math.nan)),
)
def test_crop_keeps_exactly_the_samples_in_its_interval(trial, start, stop):
    lo = -math.inf if start is None else start
    hi = math.inf if stop is None else stop
    keep = (trial.time >= lo) & (trial.time <= hi)
    if np.count_nonzero(keep) < 2:
        with pytest.raises(TrialError, match="leaves"):
            trial.crop(start, stop)
        return
    cut = trial.crop(start, stop)
    np.testing.assert_array_equal(cut.time, trial.time[keep])
    for name, xyz in trial.markers.items():
        np.testing.assert_array_equal(cut.markers[name], xyz[keep])
    for a, b in zip(trial.force_plates, cut.force_plates, strict=True):
        assert np.all((b.time >= lo) & (b.time <= hi))
        np.testing.assert_array_equal(b.force, a.force[(a.time >= lo) & (a.time <= hi)])


@examples(ci=12, long=300)
@given(trial=trials(), max_gap=st.one_of(st.floats(0.0, 0.1), st.just(math.inf)))
def test_fill_gaps_fills_short_interior_gaps_only(trial, max_gap):
    filled = trial.fill_gaps(max_gap)
    short = {
        (g.marker, g.start, g.stop)
        for g in trial.gaps()
        if not g.at_edge and g.duration <= max_gap + 1e-12
    }
    for name, xyz in trial.markers.items():
        out = filled.markers[name]
        measured = ~np.isnan(xyz).any(axis=1)
        np.testing.assert_array_equal(out[measured], xyz[measured])
        for g in trial.gaps():
            if g.marker != name:
                continue
            part = out[g.start : g.stop]
            if (name, g.start, g.stop) in short:
                assert np.all(np.isfinite(part))
            else:
                assert np.all(np.isnan(part))


@pytest.mark.parametrize("max_gap", [-1.0, math.nan, "0.1", None])
def test_a_max_gap_that_is_not_a_duration_is_named(max_gap):
    trial = Trial(np.arange(4) / 100.0, {"m1": np.zeros((4, 3))})
    with pytest.raises((ValueError, TypeError), match="max_gap"):
        trial.fill_gaps(max_gap)
