"""A recording of the wrong kind of test is refused, saying why; those of the right kind pass.

A deployment given to the pull analysis reported a maximum force 394 % off, and to the vibration
analysis a 4.8 % damping ratio. Each protocol now checks that a record is of its kind first
(module docs of `tapespring.protocols.pull`, `.vibration`, `.deployment`); the thresholds are
loose, so generated records of the right kind, over wide ranges of their parameters, all pass.
"""

import re

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st
from property_settings import examples
from tapespring.protocols import analyze_deployment, analyze_pull_trial, analyze_vibration
from tapespring.trials import ForcePlate, Trial, TrialError
from tapespring.trials.samples import (
    make_deployment_trial,
    make_pull_test_trial,
    make_vibration_trial,
)

senses = st.sampled_from(["opposite", "equal"])
seeds = st.integers(0, 2**16)


# A TrialWarning (the sense check's) is the analysis' own; every other warning is an error
# (pyproject's filterwarnings), so no numpy warning leaks.
pytestmark = pytest.mark.filterwarnings("ignore::tapespring.trials.TrialWarning")


@examples(ci=10, long=150)
@given(
    log_speed=st.floats(np.log10(0.2e-3), np.log10(10e-3)),  # 0.2 to 10 mm/s
    travel=st.floats(1e-3, 30e-3),
    buckle_at=st.floats(0.2, 0.9),  # of the travel
    max_force=st.floats(2.0, 20.0),
    noise=st.floats(0.0, 0.1),  # force noise over the maximum force
    residual=st.floats(0.2, 0.8),
    start=st.floats(0.2, 1.0),
    seed=seeds,
)
# The long profile's: the raw last sample, 2.6 noise deviations above the force after buckling
# (1.5 N), outran the smoothed peak (2 N, lowered by the window across the drop) and read as a
# maximum at the record's end; the maximum is now taken where the smoothing is complete.
@example(
    log_speed=-2.9665264331637853,
    travel=0.006759906304729689,
    buckle_at=0.5,
    max_force=2.0,
    noise=0.09375,
    residual=0.75,
    start=0.5859375,
    seed=65535,
)
# And a record that ends 25 ms after a drop to 75 %, which the smoothing shows as 89 % (no
# "buckled"): its maximum is 124 samples before the end, which a check reaching 151 samples
# back refused.
@example(
    log_speed=-2.0,
    travel=0.001,
    buckle_at=0.75,
    max_force=2.0,
    noise=0.0,
    residual=0.75,
    start=1.0,
    seed=0,
)
# And one ending 12.5 ms (50 samples) after that drop: its maximum 86 samples before the end,
# 36 before the last complete window, within the half span the check reads as a record cut
# while rising; the smoothed force falls by 11 % after it, which a rising force does not.
@example(
    log_speed=-2.0,
    travel=0.001,
    buckle_at=0.875,
    max_force=2.0,
    noise=0.0,
    residual=0.75,
    start=1.0,
    seed=0,
)
def test_generated_pull_tests_pass_the_pull_check(
    log_speed, travel, buckle_at, max_force, noise, residual, start, seed
):
    speed = 10**log_speed
    # At most 60 s of record, the whole travel in it: a record cut before the buckle is refused
    # by the pull check ("the force record ends before its maximum", as it should).
    travel = min(travel, speed * (60.0 - start))
    trial = make_pull_test_trial(
        max_force,
        buckle_at * travel,
        seed=seed,
        speed=speed,
        duration=start + travel / speed,
        start_time=start,
        force_sd=noise * max_force,
        residual_fraction=residual,
    )
    result = analyze_pull_trial(trial)
    assert result.test.max_force > 0


@examples(ci=8, long=100)
@given(sense=senses, seed=seeds, spread=st.floats(0.0, 0.05), duration=st.floats(1.0, 10.0))
def test_a_deployment_is_not_a_pull_test(sense, seed, spread, duration):
    trial, _ = make_deployment_trial(sense, seed=seed, spread=spread, duration=duration)
    with pytest.raises(TrialError, match="not a pull test: the pulled marker 'M2' covers") as info:
        analyze_pull_trial(trial)
    # The deployment's swing is named: its speed, far beyond a quasi-static pull's.
    assert "a quasi-static pull is slow" in str(info.value)


def _with_force(trial: Trial, force: np.ndarray) -> Trial:
    plate = trial.force_plate(0)
    new = ForcePlate(plate.time, np.column_stack((plate.force[:, :2], force)), plate.moment)
    return Trial(trial.time, trial.markers, (new,), trial.metadata)


def test_a_pull_without_a_pulling_force_is_refused():
    trial = make_pull_test_trial(seed=1, duration=4.0, force_sd=0.0)
    weight_only = _with_force(trial, np.full(trial.force_plate(0).time.size, -5.0))
    with pytest.raises(TrialError, match="not a pull test: the vertical force never rises"):
        analyze_pull_trial(weight_only)


def test_a_marker_moved_back_and_forth_slowly_is_not_one_pull():
    trial = make_pull_test_trial(seed=2, duration=8.0)
    t = trial.time
    markers = dict(trial.markers)
    # Three slow cycles of 5 mm (2.5 mm/s at most): slow, but no one-way pull.
    m2 = np.array(markers["M2"])
    m2[:, 2] = -0.01 - 2.5e-3 * (1.0 - np.cos(2 * np.pi * t / (t[-1] / 3)))
    markers["M2"] = m2
    cycled = Trial(t, markers, trial.force_plates, trial.metadata)
    # Down and up three times: five turns (a pull and its return would be one).
    with pytest.raises(TrialError, match=r"turns back 5 times by more than 20 % of its 4\.\d+ mm"):
        analyze_pull_trial(cycled)


def test_a_marker_that_barely_moves_is_not_pulled():
    trial = make_vibration_trial(seed=3, duration=3.0)  # M2 at rest, M3 vibrating
    plate = make_pull_test_trial(seed=3, duration=3.0).force_plate(0)
    with pytest.raises(TrialError, match=r"moves by 0\.\d+ mm at most \(a pull test moves it by"):
        analyze_pull_trial(Trial(trial.time, trial.markers, (plate,), trial.metadata))


@examples(ci=10, long=150)
@given(
    damping_ratio=st.floats(0.004, 0.03),
    period=st.floats(0.05, 0.2),
    amplitude=st.floats(5e-3, 10e-3),
    sign=st.sampled_from([-1.0, 1.0]),
    noisy=st.booleans(),
    seed=seeds,
)
def test_generated_free_decays_pass_the_decay_check(
    damping_ratio, period, amplitude, sign, noisy, seed
):
    trial = make_vibration_trial(
        damping_ratio,
        period,
        amplitude=sign * amplitude,
        seed=seed,
        marker_sd=0.05e-3 if noisy else 0.0,
    )
    # At least 3 peaks reach the window (10 s from 10 mm at 3 % at most) and the fit takes them
    # (it refused 1 decay in 40 here, "the selected peaks do not alternate": about the
    # equilibrium taken from the record's end the window kept one kind of peak only).
    result = analyze_vibration(trial)
    # And fits it: the marker noise (0.05 mm on decays of 5 to 10 mm, 40 to 160 samples a period)
    # moves the damping ratio by up to 1.1 %, measured over 600 random decays; 3 % asked.
    assert result.fit.damping_ratio == pytest.approx(damping_ratio, rel=0.03)


@examples(ci=12, long=300)
@given(
    log_damping=st.floats(-3.0, np.log10(0.3)),
    period=st.floats(0.05, 0.3),
    rate=st.sampled_from([200.0, 400.0, 800.0, 1000.0]),
    amplitude=st.floats(5e-3, 10e-3),
    sign=st.sampled_from([-1.0, 1.0]),
    noise=st.floats(0.0, 0.05e-3),
    duration=st.floats(2.0, 10.0),
    seed=seeds,
)
def test_a_free_decay_is_fitted_unless_fewer_than_3_peaks_reach_the_window(
    log_damping, period, rate, amplitude, sign, noise, duration, seed
):
    # Damping ratios 0.1 to 30 %: the records may stop long before the window, or cross it in
    # two half periods. Either the fit is made, with the right period, or it says that fewer
    # than 3 peaks are in the window; a free decay is never refused as another kind of record.
    damping_ratio = 10**log_damping
    trial = make_vibration_trial(
        damping_ratio,
        period,
        amplitude=sign * amplitude,
        seed=seed,
        marker_sd=noise,
        marker_rate=rate,
        duration=duration,
    )
    try:
        result = analyze_vibration(trial)
    except TrialError as exc:
        assert re.search(r"damping fit impossible: only [012] peak\(s\)", str(exc)), str(exc)
    else:
        # The peaks span k half periods; one miscounted would put the period 1 / k off.
        fit = result.fit
        k = round((fit.peak_time[-1] - fit.peak_time[0]) / (period / 2))
        assert fit.period == pytest.approx(period, rel=0.5 / k)


def test_an_undamped_vibration_passes_and_a_growing_one_does_not():
    steady = make_vibration_trial(0.0, 0.1, amplitude=-3e-3, duration=3.0, marker_sd=0.0)
    result = analyze_vibration(steady)
    assert abs(result.fit.damping_ratio) < 1e-4
    growing = make_vibration_trial(-0.02, 0.1, amplitude=-1e-3, duration=2.0, seed=4)
    with pytest.raises(TrialError, match=r"not a free decay: (\d+) of its \1 peaks after the"):
        analyze_vibration(growing)


@examples(ci=8, long=100)
@given(sense=senses, seed=seeds, spread=st.floats(0.0, 0.05), duration=st.floats(3.0, 10.0))
def test_a_deployment_is_not_a_free_decay(sense, seed, spread, duration):
    # From 3 s on, a synthetic deployment reaches its fast phases and its 0.4-4 mm peaks; a
    # shorter one has none in the window, and the fit says so.
    trial, _ = make_deployment_trial(sense, seed=seed, spread=spread, duration=duration)
    with pytest.raises(TrialError, match="not a free decay: .* a deployment record"):
        analyze_vibration(trial)


@pytest.mark.parametrize(
    ("sense", "duration", "message"),
    [
        # Too short to reach the window: the fit says so (at 2 s in opposite sense, about the
        # midline of the deployed swings; about the median of the last quarter, the free-decay
        # check spoke first).
        ("opposite", 1.0, "damping fit impossible: only 0"),
        ("equal", 1.5, "damping fit impossible: only 0"),
        ("equal", 2.0, "damping fit impossible: only 0"),
        ("opposite", 2.0, "damping fit impossible: only 0"),
        # Long enough: the free-decay check speaks first.
        ("opposite", 3.0, "not a free decay"),
    ],
)
def test_a_short_deployment_is_refused_as_a_free_decay_too(sense, duration, message):
    trial, _ = make_deployment_trial(sense, seed=0, spread=0.05, duration=duration)
    with pytest.raises(TrialError, match=message):
        analyze_vibration(trial)


@examples(ci=8, long=100)
@given(seed=seeds, duration=st.floats(2.0, 16.0))
def test_a_pull_test_is_not_a_deployment(seed, duration):
    trial = make_pull_test_trial(seed=seed, duration=duration)
    with pytest.raises(TrialError, match="is held at|never leaves|no peak found"):
        analyze_deployment(trial)


@examples(ci=8, long=100)
@given(seed=seeds, tilt=st.floats(2.5, 10.0))
def test_a_free_decay_is_not_a_deployment(seed, tilt):
    # The free end turns by a few degrees as the tip vibrates (the simulated decay: 4 deg); the
    # synthetic decay keeps markers 1 and 2 at rest, so turn marker 2 with the tip here (by more
    # than the 2 deg that mark a release, or the angle "never leaves its initial value").
    trial = make_vibration_trial(seed=seed, duration=4.0)
    markers = {k: np.array(v) for k, v in trial.markers.items()}
    z3 = markers["M3"][:, 2] - markers["M3"][-1, 2]
    markers["M2"][:, 2] += 0.05 * np.tan(np.deg2rad(tilt) * z3 / np.max(np.abs(z3)))
    moving = Trial(trial.time, markers, (), trial.metadata)
    with pytest.raises(TrialError, match=r"is held at [+-]\d\.\d deg .* not a deployment record"):
        analyze_deployment(moving)
