"""Trial data model: validation, gap reporting and gap filling."""

import numpy as np
import pytest
from tapespring.trials import ForcePlate, Metadata, Trial, TrialError


def _trial(n=200, rate=800.0, **markers):
    t = np.arange(n) / rate
    if not markers:
        markers = {"M1": np.column_stack((np.sin(t), np.cos(t), t))}
    return Trial(time=t, markers=markers, metadata=Metadata(name="demo"))


def test_gaps_are_reported_with_position_and_duration():
    t = np.arange(100) / 100.0
    xyz = np.column_stack((t, t, t))
    xyz[10:13, 0] = np.nan  # 3 samples, one coordinate is enough
    xyz[95:, :] = np.nan  # touches the end
    trial = Trial(time=t, markers={"A": xyz, "B": np.zeros((100, 3))})
    gaps = trial.gaps()
    assert [(g.marker, g.start, g.stop, g.at_edge) for g in gaps] == [
        ("A", 10, 13, False),
        ("A", 95, 100, True),
    ]
    assert gaps[0].duration == pytest.approx(0.03)
    assert gaps[0].start_time == pytest.approx(0.10)
    assert gaps[0].n_samples == 3


def test_fill_gaps_interpolates_only_short_interior_gaps():
    t = np.arange(400) / 800.0
    truth = np.column_stack((np.sin(5 * t), np.cos(3 * t), t**2))
    xyz = truth.copy()
    xyz[50:54] = np.nan  # 5 ms: filled with max_gap = 10 ms
    xyz[200:240] = np.nan  # 50 ms: kept
    xyz[:3] = np.nan  # at the start: never extrapolated
    filled = Trial(time=t, markers={"M": xyz}).fill_gaps(max_gap=0.010)
    out = filled.markers["M"]
    # A cubic spline through samples of a smooth signal at 800 Hz: interpolation
    # error ~ h^4 f''''/384 with h = 6.25 ms over a 5-sample gap, f'''' <= 625: < 1e-8.
    np.testing.assert_allclose(out[50:54], truth[50:54], atol=1e-7)
    assert np.isnan(out[200:240]).all()
    assert np.isnan(out[:3]).all()
    assert len(filled.gaps()) == 2


def test_fill_gaps_without_gaps_returns_same_trial():
    trial = _trial()
    assert trial.fill_gaps(0.1) is trial


def test_marker_shape_mismatch_names_the_source():
    with pytest.raises(TrialError, match=r"demo.*marker 'M1' has shape \(5, 3\)"):
        Trial(
            time=np.arange(10) / 10,
            markers={"M1": np.zeros((5, 3))},
            metadata=Metadata(name="demo"),
        )


def test_non_uniform_time_is_an_inconsistent_rate():
    t = np.arange(100) / 800.0
    t[50:] += 0.0005
    with pytest.raises(TrialError, match="inconsistent marker sampling rate"):
        Trial(time=t, markers={"M": np.zeros((100, 3))})


def test_missing_marker_lists_available_ones():
    with pytest.raises(TrialError, match=r"missing marker 'M9' \(available: M1\)"):
        _trial().marker("M9")


def test_unknown_sense_is_rejected():
    with pytest.raises(TrialError, match="sense must be one of"):
        Metadata(sense="sideways")


def test_force_plate_rate_and_shape_checks():
    t = np.arange(1000) / 1000.0
    plate = ForcePlate(time=t, force=np.zeros((1000, 3)), moment=np.zeros((1000, 3)))
    assert plate.rate == pytest.approx(1000.0)
    with pytest.raises(TrialError, match="force has shape"):
        ForcePlate(time=t, force=np.zeros((999, 3)), moment=np.zeros((1000, 3)))


def test_trial_arrays_are_read_only():
    trial = _trial()
    with pytest.raises(ValueError, match="read-only"):
        trial.markers["M1"][0, 0] = 1.0


def test_crop_keeps_the_interval_and_cuts_the_force_plates():
    t = np.arange(100) / 100.0
    plate = ForcePlate(np.arange(200) / 200.0, np.ones((200, 3)), np.zeros((200, 3)))
    trial = Trial(t, {"A": np.column_stack((t, t, t))}, (plate,))
    part = trial.crop(0.2, 0.5)
    assert part.time[0] == pytest.approx(0.2) and part.time[-1] == pytest.approx(0.5)
    assert part.markers["A"].shape == (31, 3)
    assert part.force_plates[0].time[0] == pytest.approx(0.2)
    with pytest.raises(TrialError, match="leaves 1 marker sample"):
        trial.crop(0.5, 0.5)
