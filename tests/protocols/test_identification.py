"""Static identification protocol (paper Sec. 5.1, Table 3) on synthetic trials with known
displacements: a record at rest in the unfolded equilibrium, a smooth fold, at rest in the folded
one, with the paper's marker noise (0.05 mm along x and z, 0.3 mm along y)."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
from _identification import TABLE3, identification_trial
from tapespring.protocols import KINDS, analyze_identification, analyze_trials, protocol_for
from tapespring.protocols.identification import (
    CONTROL_TOLERANCE,
    MIN_REST_SAMPLES,
    MIN_TIP_DISPLACEMENT,
    REST_TOLERANCE,
    REST_WINDOW,
)
from tapespring.report import format_summary, summary_dict, write_report
from tapespring.trials import Trial, TrialError, TrialWarning
from tapespring.trials.samples import MARKER_SD, MARKER_SD_TRANSVERSE, make_vibration_trial


def test_table3_displacements_are_recovered():
    r = analyze_identification(identification_trial())
    # The difference of two medians over 401 samples has a standard deviation of
    # sqrt(2) 1.2533 sigma / sqrt(401) (4.4 um along x and z, 27 um along y): within 4 of them.
    sd = np.array([MARKER_SD, MARKER_SD_TRANSVERSE, MARKER_SD])
    tol = 4 * np.sqrt(2) * 1.2533 * sd / np.sqrt(401)
    np.testing.assert_array_less(np.abs(r.markers12_m - [24.7e-3, 0.1e-3, 77.9e-3]), tol)
    np.testing.assert_array_less(np.abs(r.marker3_m - [41.8e-3, 0.6e-3, 110.9e-3]), tol)
    assert r.control_m is not None
    np.testing.assert_array_less(np.abs(r.control_m - [0.2e-3, 0.1e-3, 0.1e-3]), tol)
    assert not r.control_moved
    # Absolute values, each marker's own displacement too.
    np.testing.assert_array_less(np.abs(r.displacements_m["M1"] - [24.0e-3, 0.15e-3, 77e-3]), tol)
    assert r.rest_s == REST_WINDOW and r.unfolded_window_s == (0.0, 0.5)
    assert r.folded_window_s == pytest.approx((3.5, 4.0))
    f = r.figures()
    assert f["markers12_dz_m"] == pytest.approx(77.9e-3, abs=tol[2])
    assert f["marker0_dx_m"] == pytest.approx(0.2e-3, abs=tol[0])
    json.dumps(r.summary())


def test_noise_free_displacements_are_exact():
    r = analyze_identification(identification_trial(noise=False))
    np.testing.assert_allclose(r.markers12_m, [24.7e-3, 0.1e-3, 77.9e-3], rtol=1e-12)
    np.testing.assert_allclose(r.marker3_m, [41.8e-3, 0.6e-3, 110.9e-3], rtol=1e-12)
    # Round-off only: `smooth`'s running sums leave ~5e-15 m on positions of ~0.1 m.
    assert r.rest_motion_m < 1e-13


def test_a_shorter_rest_window_and_without_control_marker():
    trial = identification_trial(noise=False, duration=3.0, fold=(0.3, 2.7))
    r = analyze_identification(trial, rest=0.25, control=None)
    assert r.control_m is None and r.figures()["marker0_dx_m"] is None
    assert "M0" not in r.displacements_m
    np.testing.assert_allclose(r.marker3_m, [41.8e-3, 0.6e-3, 110.9e-3], rtol=1e-12)
    # With the default 0.5 s, the fold (from 0.3 s) is inside the first window.
    with pytest.raises(TrialError, match="not at rest: marker 'M1' strays by"):
        analyze_identification(trial)


def test_a_moved_support_is_warned_and_reported():
    moved = dict(TABLE3, M0=(1.5e-3, 0.0, 0.2e-3))
    with pytest.warns(TrialWarning, match=r"control marker 'M0' .* moved by \(1\.5, "):
        r = analyze_identification(identification_trial(displacements=moved, noise=False))
    assert r.control_moved and r.summary()["control_moved"] is True
    assert r.control_m is not None and r.control_m[0] == pytest.approx(1.5e-3)
    assert 1.5e-3 > CONTROL_TOLERANCE  # the premise: a move beyond the threshold
    # Not corrected for it: markers 1-3 as recorded.
    np.testing.assert_allclose(r.marker3_m, [41.8e-3, 0.6e-3, 110.9e-3], rtol=1e-12)


def test_too_short_a_record_is_refused():
    trial = identification_trial(duration=0.9, fold=(0.3, 0.6))
    with pytest.raises(TrialError, match=r"too short .* lasts 0\.9 s, .* need 1 s at least"):
        analyze_identification(trial)
    # Long enough, but too few samples in a window (10 Hz: 5 in 0.5 s).
    slow = identification_trial(rate=10.0, noise=False)
    with pytest.raises(TrialError, match=f"6 sample\\(s\\) .* needs {MIN_REST_SAMPLES} at least"):
        analyze_identification(slow)


def test_a_record_still_swinging_at_its_end_is_not_at_rest():
    # A 9 Hz swing at 1 % damping keeps 60 % of its amplitude 0.9 s after the fold, where the
    # last window starts: from 2 mm, 1.2 mm there, more than the 0.65 mm allowed along z.
    with pytest.raises(TrialError, match=r"not at rest: marker 'M1' strays by 1\.\d+ mm along z"):
        analyze_identification(identification_trial(swing=2e-3))
    # From 0.15 mm, 0.09 mm: within REST_TOLERANCE, at rest.
    r = analyze_identification(identification_trial(swing=0.15e-3))
    assert r.rest_motion_m < REST_TOLERANCE


def test_a_record_starting_during_the_fold_is_not_at_rest():
    with pytest.raises(TrialError, match=r"not at rest: .* unfolded equilibrium's rest window"):
        analyze_identification(identification_trial(fold=(0.2, 2.0)))


def test_a_missing_or_unseen_marker_is_named():
    trial = identification_trial()
    markers = dict(trial.markers)
    del markers["M0"]
    no_control = Trial(trial.time, markers, metadata=trial.metadata)
    with pytest.raises(TrialError, match="missing marker 'M0', marker 0 .*: M1, M2, M3"):
        analyze_identification(no_control)
    with pytest.raises(TrialError, match="'M4'"):
        analyze_identification(trial, markers=("M1", "M2", "M4"))
    # M3 lost at the end of the record: no samples in the folded window.
    m3 = np.array(trial.markers["M3"])
    m3[trial.time > 3.0] = np.nan
    lost = Trial(trial.time, dict(trial.markers, M3=m3), metadata=trial.metadata)
    with pytest.raises(TrialError, match=r"marker 'M3' has 0 sample\(s\) in the folded"):
        analyze_identification(lost)


def test_gaps_outside_the_rest_windows_do_not_matter():
    trial = identification_trial(noise=False)
    m2 = np.array(trial.markers["M2"])
    m2[(trial.time > 1.5) & (trial.time < 2.0)] = np.nan  # hidden by the hand during the fold
    m2[5] = np.nan  # one sample lost in the first window
    r = analyze_identification(Trial(trial.time, dict(trial.markers, M2=m2)))
    np.testing.assert_allclose(r.markers12_m, [24.7e-3, 0.1e-3, 77.9e-3], rtol=1e-12)


def test_a_record_without_a_fold_is_refused():
    small = {k: tuple(0.1 * np.asarray(v)) for k, v in TABLE3.items()}  # tip 11.8 mm
    with pytest.raises(TrialError, match=r"not a static identification test: marker 3 \('M3'\)"):
        analyze_identification(identification_trial(displacements=small))
    assert 11.8e-3 < MIN_TIP_DISPLACEMENT  # the premise: a tip move below the threshold
    # A free decay (its tip starts 8 mm down, and swings): refused either way.
    decay = make_vibration_trial(duration=3.0)
    with pytest.raises(TrialError):
        analyze_identification(decay, control=None)


def test_bad_options_are_refused():
    trial = identification_trial(noise=False)
    for rest in (0.0, -1.0, float("nan"), float("inf"), "1", True):
        with pytest.raises(ValueError, match="rest must be a finite duration > 0"):
            analyze_identification(trial, rest=rest)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="markers must be 3 names"):
        analyze_identification(trial, markers=("M1", "M2"))


def test_the_kind_is_registered_and_reported(tmp_path):
    assert "identification" in KINDS
    assert protocol_for("identification").kind == "identification"
    trials = [identification_trial(seed=i, name=f"test{i}") for i in range(3)]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        analysis = analyze_trials(trials, "identification")
    s = analysis.summaries
    assert s["markers12_dx"].mean == pytest.approx(24.7e-3, abs=15e-6)
    assert s["marker3_dz"].mean == pytest.approx(110.9e-3, abs=15e-6)
    assert s["marker0_dx"].count == 3
    text = format_summary(analysis)
    assert "identification: 3 trial(s)" in text and "markers 1-2 x displacement" in text
    data = summary_dict(analysis)
    assert data["markers12_dz_m"]["mean"] == pytest.approx(77.9e-3, abs=15e-6)  # type: ignore[index]
    json.dumps(data)
    files = write_report(analysis, tmp_path / "report")
    assert {f.name for f in files} == {"summary.csv", "trials.csv", "identification.png"}
    rows = (tmp_path / "report" / "trials.csv").read_text().splitlines()
    assert len(rows) == 4 and rows[1].startswith("test0")


def test_trials_analyze_command(tmp_path, capsys):
    from tapespring.cli import main
    from tapespring.trials.csv import write_csv

    folder = tmp_path / "static"
    for i in range(2):
        write_csv(identification_trial(seed=i), folder / f"trial{i}.csv")
    out = tmp_path / "report"
    argv = ["trials", "analyze", str(folder), "--kind", "identification", "--out", str(out)]
    assert main([*argv, "--no-progress", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["kind"] == "identification" and data["n_trials"] == 2
    assert data["marker3_dx_m"]["mean"] == pytest.approx(41.8e-3, abs=1e-5)
    # A bad trial: exit 1 with the problem named.
    write_csv(identification_trial(duration=0.8, fold=(0.2, 0.5)), folder / "short.csv")
    assert main([*argv, "--no-progress"]) == 1
    assert "too short" in capsys.readouterr().err
